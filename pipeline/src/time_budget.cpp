#include "time_budget.h"

#include <algorithm>
#include <atomic>
#include <cstdio>

namespace pnpba {

namespace {

constexpr int kStages = 7;

// Each stage's typical time at 640 x 480 on a 2-core machine (latency_bench's stage medians over
// the rendered sweep, 2026-12-01, with every stage timed under an endless budget): the check of an
// accepted feature pose 1.5 ms (the textbook pair 1.3, the poster 0.6), the depth path's alignment
// of a feature pose 9 ms (the poor room), the SIFT retry 31 ms (the rich room at 60 degrees), the
// global registration 10 ms per thousand points it is predicted to keep (registration_work.h; the
// rendered rooms 8.1-12.3, about 32 ms a pair, the real cabinet 9.0, 11-15 ms), and the
// alignment and judging of one more candidate 8 ms (the cabinet), and within it the evidence of
// an aligned candidate, measured in one piece, 3 ms (2.3 on average over the real cabinet's
// pairs, 2-4 at 640 x 480; 2026-12-01, later). The expectations start here and
// then follow what the stages take in this process; a stage a budget always cuts never corrects its
// expectation, so these are kept near what the stages take now, not what they took before they were
// made faster (a 60 ms SIFT retry, for one, was cut under a 66 ms budget where it would have
// fitted). The opening of the registration's plugin 60 ms: 56-182 ms in a command-line run on the
// real cabinet, 23-55 in a process with more of Open3D's libraries loaded (2026-12-02).
constexpr double kTypicalMs[kStages] = {1.5, 9.0, 31.0, 10.0, 8.0, 3.0, 60.0};

// What each stage took last, averaged: half the last time, half the expectation before. Shared
// by the estimates a process runs, on any thread; a race between two updates loses one of them,
// which an average of times does not mind.
std::atomic<double>& expectation(BudgetedStage stage) {
  static std::atomic<double> expected[kStages] = {kTypicalMs[0], kTypicalMs[1], kTypicalMs[2],
                                                  kTypicalMs[3], kTypicalMs[4], kTypicalMs[5],
                                                  kTypicalMs[6]};
  return expected[static_cast<int>(stage)];
}

}  // namespace

const char* toString(BudgetedStage stage) {
  switch (stage) {
    case BudgetedStage::kFeatureCheck:
      return "check of the feature pose";
    case BudgetedStage::kSeedAlignment:
      return "alignment of the feature pose";
    case BudgetedStage::kSiftRetry:
      return "SIFT retry";
    case BudgetedStage::kRegistration:
      return "global registration";
    case BudgetedStage::kCandidateAlignment:
      return "alignment of a registration candidate";
    case BudgetedStage::kEvidence:
      return "evidence of an aligned candidate";
    case BudgetedStage::kPluginOpening:
      return "opening of the registration's plugin";
  }
  return "stage";
}

double TimeBudget::expectedMs(BudgetedStage stage) {
  return expectation(stage).load(std::memory_order_relaxed);
}

bool TimeBudget::allows(BudgetedStage stage, double work, double then_ms) {
  if (!(budget_ms_ > 0)) return true;
  const double spent = std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
  const double expected = expectedMs(stage) * std::max(work, 0.0) + std::max(then_ms, 0.0);
  if (spent + expected <= budget_ms_) return true;
  if (!cut()) {
    char text[240];
    if (then_ms > 0) {
      std::snprintf(text, sizeof text,
                    "the time budget of %.4g ms: %.1f ms spent, the %s (about %.0f ms, and %.0f "
                    "for what it needs after it) did not fit",
                    budget_ms_, spent, toString(stage), expected - then_ms, then_ms);
    } else {
      std::snprintf(text, sizeof text,
                    "the time budget of %.4g ms: %.1f ms spent, the %s (about %.0f ms) did not fit",
                    budget_ms_, spent, toString(stage), expected);
    }
    cut_message_ = text;
    // Once a process: say how a loop keeps it out of every pair.
    if (stage == BudgetedStage::kPluginOpening) {
      cut_message_ +=
          " (once a process: a loop opens it before its first pair with "
          "preloadDepthRegistration(), in Python preload_depth_registration())";
    }
  }
  return false;
}

TimeBudget::Clock::time_point TimeBudget::deadline() const {
  // A budget of years is none (and past the clock's range).
  if (!(budget_ms_ > 0) || budget_ms_ > 1e12) return Clock::time_point::max();
  return start_ + std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double, std::milli>(budget_ms_));
}

bool TimeBudget::ranOutDuring(BudgetedStage stage) {
  const Clock::time_point now = Clock::now();
  if (now < deadline()) return false;
  if (!cut()) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "the time budget of %.4g ms: %.1f ms spent, the %s was cut off at it", budget_ms_,
                  std::chrono::duration<double, std::milli>(now - start_).count(), toString(stage));
    cut_message_ = text;
  }
  return true;
}

void TimeBudget::record(BudgetedStage stage, double ms, double work) const {
  if (!(budget_ms_ > 0) || !(ms >= 0) || !(work > 0)) return;
  std::atomic<double>& e = expectation(stage);
  // Never below a tenth of a millisecond: a stage always costs something, so a budget already
  // spent cuts it.
  e.store(std::max(0.1, 0.5 * e.load(std::memory_order_relaxed) + 0.5 * ms / work),
          std::memory_order_relaxed);
}

}  // namespace pnpba
