#!/usr/bin/env bash
# Fuzzes every reader of untrusted text: builds the libFuzzer targets of fuzz/ with clang,
# AddressSanitizer and UndefinedBehaviorSanitizer into build-fuzz/, seeds each from the
# project's and the shared data, and runs each for SECONDS (default 60).
# Exits non-zero on any crash, leak, sanitizer report or hang (> 10 s on one input), after
# printing the reproducer's path; rerun one with build-fuzz/fuzz/fuzz_<name> <reproducer>.
set -euo pipefail
seconds="${1:-60}"
case "$seconds" in '' | *[!0-9]*) echo "usage: scripts/fuzz.sh [SECONDS]" >&2; exit 2 ;; esac
root="$(cd "$(dirname "$0")/.." && pwd)"
shared="${PNPBA_SHARED_DATA:-$root/../shared/data}"
build="$root/build-fuzz"
"$root/scripts/setup.sh" clang libclang-rt-14-dev

targets=(bal tum_lists camera_yaml pairs_file direct_files)
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DPNPBA_FUZZ=ON -DPNPBA_BUILD_TESTS=OFF -DPNPBA_BUILD_BENCH=OFF -DPNPBA_BUILD_APPS=OFF -DPNPBA_BUILD_PYTHON=OFF \
    >/dev/null
fi
cmake --build "$build" -j2 --target "${targets[@]/#/fuzz_}"

# Seeds: every file of a kind we have, a selector byte first where one target reads several.
seeds="$build/seeds"
rm -rf "$seeds"
mkdir -p "${targets[@]/#/$seeds/}"
seed() {  # seed TARGET PREFIX FILE...
  local target="$1" prefix="$2"
  shift 2
  local f
  for f in "$@"; do
    [ -f "$f" ] || continue
    { printf '%s' "$prefix"; head -c 65536 "$f"; } >"$seeds/$target/$(basename "$(dirname "$f")")-$(basename "$f")"
  done
}
seed bal "" "$shared"/bal/*.txt
seed tum_lists $'\x00' "$shared"/tum_fr1_desk/rgb.txt "$shared"/tum_fr1_desk/depth.txt
seed tum_lists $'\x01' "$shared"/tum_fr1_desk/associate.txt
seed tum_lists $'\x02' "$shared"/tum_fr1_desk/groundtruth.txt
seed camera_yaml "" "$root"/data/images/camera.yaml
seed pairs_file "" "$shared"/reference/ch7_pairs_75.txt
seed direct_files $'\x00' "$shared"/direct_ba/poses.txt
seed direct_files $'\x01' "$shared"/direct_ba/points.txt

status=0
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  findings="$build/findings/$t"
  mkdir -p "$corpus" "$findings"
  log="$build/findings/$t.log"
  echo "fuzz: $t for ${seconds} s"
  if ! "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=8192 -print_final_stats=0 -artifact_prefix="$findings/" \
    "$corpus" "$seeds/$t" >"$log" 2>&1; then
    status=1
    echo "fuzz: $t FAILED; log: $log"
    grep -E "^SUMMARY|ERROR:" "$log" | head -3 || true
    for f in "$findings"/*; do [ -f "$f" ] && echo "fuzz: reproducer: $f"; done
  else
    grep -E "^Done [0-9]+ runs" "$log" | sed "s/^/fuzz: $t: /" || true
  fi
done
exit $status
