#!/usr/bin/env bash
# pip's front door: `pip install --no-build-isolation .` into a fresh virtual environment made
# with --system-site-packages installs the module (with its plugins beside it) and the
# pnpba-batch command, and both give the CLI's T. The CMake build is the test's own
# (PNPBA_CMAKE_BUILD_DIR), so only the install is exercised here, not a second full build.
set -euo pipefail
build="$1" source="$2" python="$3" cli="$4"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$python" -m venv --system-site-packages "$work/venv"
(cd "$source" && PNPBA_CMAKE_BUILD_DIR="$build" "$work/venv/bin/pip" install -q \
  --no-build-isolation --no-deps --no-index . >"$work/pip.log" 2>&1) || {
  cat "$work/pip.log"
  exit 1
}
img="$source/data/images"
printf 'id\trgb1\tdepth1\trgb2\tdepth2\np\t%s\t%s\t%s\t%s\n' "$img/1.png" "$img/1_depth.png" \
  "$img/2.png" "$img/2_depth.png" >"$work/pairs.tsv"
"$cli" "$img/1.png" "$img/2.png" "$img/1_depth.png" "$img/2_depth.png" \
  --camera "$img/camera.yaml" --json "$work/cli.json" >/dev/null
cd "$work"  # not the source tree: the venv's module, not python/pnpba
env -u PYTHONPATH "$work/venv/bin/pnpba-batch" pairs.tsv --output batch.jsonl \
  --camera "$img/camera.yaml" --quiet 2>/dev/null
env -u PYTHONPATH "$work/venv/bin/python" - "$work" <<'PY'
import json, os, sys
import numpy as np, pnpba
work = sys.argv[1]
assert pnpba.__file__.startswith(os.path.join(work, "venv")), pnpba.__file__
plugins = os.path.join(os.path.dirname(pnpba.__file__), "pnpba")
assert os.path.isfile(os.path.join(plugins, "libpnpba_open3d.so")), os.listdir(plugins)
cli = np.array(json.load(open(f"{work}/cli.json"))["T"])
batch = np.array(json.loads(open(f"{work}/batch.jsonl").readline())["T"])
assert np.abs(batch - cli).max() < 1e-9, (batch, cli)
print("pip: the venv's module and pnpba-batch agree with the CLI")
PY
