#!/usr/bin/env bash
# Installs the Debian packages pnpba needs to build and test, and any named as arguments. Idempotent: when every package is
# already present it installs nothing and prints nothing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config ccache
  libeigen3-dev libceres-dev
  # OpenCV per-module packages only: the full libopencv-dev tree pulls in far more than we use.
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  libopencv-features2d-dev libopencv-calib3d-dev
  # PNG and JPEG decoded without OpenCV's imgcodecs and the 120 libraries it loads.
  libpng-dev libjpeg-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev
  # Threads of the dense alignment and the registration's RANSAC.
  libtbb-dev
  # Depth-only registration of texture-poor pairs (FPFH, RANSAC, point-to-plane ICP).
  libopen3d-dev
  # The Python module and its tests; OpenCV's Python bindings for the examples and tests.
  pybind11-dev python3-dev python3-numpy python3-pytest python3-opencv
  # The batch runner (pnpba.batch): Dask and its progress bar.
  python3-distributed python3-tqdm
)
# Callers may ask for more (scripts/fuzz.sh: clang and its fuzzer runtime).
packages+=("$@")

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "setup: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq >/dev/null
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
