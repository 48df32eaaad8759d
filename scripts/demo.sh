#!/usr/bin/env bash
# Builds if needed, then estimates the two-view pose of the project's synthetic RGB-D pair
# (data/images/, made by apps/render_synthetic) and compares it with the ground truth.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh" >/dev/null
img="$root/data/images"
echo "== pose_estimation_3d2d on data/images (default: rgbd BA) =="
"$root/build/apps/pose_estimation_3d2d" "$img/1.png" "$img/2.png" "$img/1_depth.png" \
  "$img/2_depth.png" --camera "$img/camera.yaml"
echo
echo "== ground truth (data/images/T_21.txt) =="
grep -v '^#' "$img/T_21.txt"
