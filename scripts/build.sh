#!/usr/bin/env bash
# Configures (Release, once) and builds pnpba into build/ (or $PNPBA_BUILD_DIR) with two jobs.
# Installs missing packages first. Extra arguments go to the configure step, e.g.
# -DPNPBA_SHARED_DATA=/path.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${PNPBA_BUILD_DIR:-$root/build}"
"$root/scripts/setup.sh"
if [ ! -f "$build/CMakeCache.txt" ] || [ $# -gt 0 ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
fi
cmake --build "$build" -j2
