#!/usr/bin/env bash
# Installs what is missing, builds (Release, -j2) and runs every test.
#   scripts/test.sh [CMAKE_ARGS...]             into build/
#   scripts/test.sh --sanitize [CMAKE_ARGS...]  the same suite built with AddressSanitizer and
#                                               UndefinedBehaviorSanitizer, into build-sanitize/
#                                               (any report fails its test)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ "${1:-}" = "--sanitize" ]; then
  shift
  export PNPBA_BUILD_DIR="$root/build-sanitize"
  # The Python module is left out: a sanitized extension needs the runtime preloaded into
  # python3. Leaks are checked; every UB report aborts.
  set -- -DPNPBA_SANITIZE=ON -DPNPBA_BUILD_BENCH=OFF -DPNPBA_BUILD_PYTHON=OFF "$@"
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
fi
"$root/scripts/build.sh" "$@"
cd "${PNPBA_BUILD_DIR:-$root/build}"
ctest --output-on-failure
