#!/usr/bin/env bash
# Builds if needed, then solves the textbook pair's bundle adjustment (the 75 correspondences
# of shared/data/reference) with the textbook graph and with pnpba's RGB-D graph, printing T.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
data="$(sed -n 's/^PNPBA_SHARED_DATA:PATH=//p' "$root/build/CMakeCache.txt")"
pairs="$data/reference/ch7_pairs_75.txt"
if [ ! -f "$pairs" ]; then
  echo "demo: $pairs not found (configure with -DPNPBA_SHARED_DATA=<shared/data>)" >&2
  exit 2
fi
echo "== textbook graph (pose + free points, camera 2 only), g2o's LM =="
"$root/build/apps/bundle_adjust_pairs" "$pairs" --mode textbook --solver native --verbose
echo
echo "== rgbd graph (camera 1 pixel + depth, camera 2 pixel) =="
"$root/build/apps/bundle_adjust_pairs" "$pairs" --mode rgbd
