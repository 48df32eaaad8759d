// TwoViewOptions::time_budget_ms: one estimate's wall-clock budget, for a caller that needs an
// answer at a frame rate. Each optional stage (the depth path's check or alignment of the
// feature pose, the SIFT retry, the global registration, each registration candidate or twin)
// asks before it starts; it runs only when its expected time fits in what is left of the budget. A
// stage that does not fit cuts the pair short, and the driver then refuses it (rule "time_budget"):
// the evidence that stage would have added was never weighed, so whatever the stages before it
// returned is not answered either. With a budget, each pair gets the answer it gets without one,
// or this refusal.
//
// In a process that has not opened the registration's plugin yet, the first registration opens it
// first (Open3D: 25-180 ms, once): a stage of its own, weighed before the registration, so that a
// single command-line run keeps its budget too. A loop opens it before its first pair
// (preloadDepthRegistration()), where it is never weighed again.
//
// A stage that started where it fitted and then runs past the budget (the RGB-D alignment of a
// candidate, which takes two or three times its usual time on some pairs) stops at the deadline
// between two of its steps, and cuts the pair there: with a budget a pair ends within about a
// millisecond of it, the stages a budget does not weigh (the features, the registration once
// started) aside.
//
// A stage's expected time is an average of what it took before in this process (so it follows
// the machine), starting from its typical time at 640 x 480 on a 2-core machine; the global
// registration's, per thousand points it is predicted to keep (registration_work.h), since a
// small scene's takes a third of a large one's. So the answer
// depends on the machine's speed and on the pairs before it: with a budget, and only with one,
// the same input may give a different answer from one run to the next.
#pragma once

#include <chrono>
#include <string>

namespace pnpba {

// kFeatureCheck: an accepted, precise feature pose's alignment, which stops at a coarse level
// where it agrees (a few ms); kSeedAlignment: any other feature pose's, to full resolution;
// kPluginOpening: a process's first registration opening its plugin (Open3D) before it starts.
enum class BudgetedStage {
  kFeatureCheck,
  kSeedAlignment,
  kSiftRetry,
  kRegistration,
  kCandidateAlignment,
  kEvidence,
  kPluginOpening
};
const char* toString(BudgetedStage stage);

class TimeBudget {
 public:
  using Clock = std::chrono::steady_clock;
  // budget_ms 0: no budget (every stage runs).
  TimeBudget(Clock::time_point start, double budget_ms) : start_(start), budget_ms_(budget_ms) {}

  // Whether `stage` may start now, expected to take its time per unit of work times `work`, and
  // `then_ms` after it for what must follow before it can give an answer; when it may not, the
  // budget remembers the cut (cut()). A stage's work is 1, but the registration's: the thousands
  // of points it is predicted to keep (registration_work.h).
  bool allows(BudgetedStage stage, double work = 1, double then_ms = 0);
  // Records what a stage that ran took on that work, for the next estimate's expectation of it.
  void record(BudgetedStage stage, double ms, double work = 1) const;
  // Whether there is a budget at all (no work need be predicted without one).
  bool active() const { return budget_ms_ > 0; }

  // When the budget runs out (the clock's maximum without one): a long stage asks between its
  // steps whether this has passed.
  Clock::time_point deadline() const;
  // Whether the budget ran out during `stage` (its deadline passed); if so the budget is cut,
  // "the time budget of 33 ms: 33.4 ms spent, the alignment of a registration candidate was cut
  // off".
  bool ranOutDuring(BudgetedStage stage);

  bool cut() const { return !cut_message_.empty(); }
  // "the time budget of 33 ms: 12.4 ms spent, the SIFT retry (about 31 ms) did not fit".
  const std::string& cutMessage() const { return cut_message_; }

  // A stage's expected time now per unit of its work (ms), as allows() reads it.
  static double expectedMs(BudgetedStage stage);

 private:
  Clock::time_point start_;
  double budget_ms_;
  std::string cut_message_;
};

}  // namespace pnpba
