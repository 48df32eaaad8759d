#!/usr/bin/env bash
# Installs what is missing, builds (Release, -j2) and runs every test.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh" "$@"
cd "$root/build"
ctest --output-on-failure
