#!/usr/bin/env bash
# Configures (Release, once) and builds pnpba into build/ with two jobs. Installs missing
# packages first. Extra arguments go to the configure step, e.g. -DPNPBA_SHARED_DATA=/path.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/setup.sh"
if [ ! -f "$root/build/CMakeCache.txt" ] || [ $# -gt 0 ]; then
  cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
fi
cmake --build "$root/build" -j2
