#!/usr/bin/env bash
# Installs the build into a temporary prefix, then, using only that prefix:
#   - builds tests/install/consumer with find_package(pnpba) and runs it on data/images/;
#   - imports the installed Python module and estimates the same pair;
# and checks that both give the installed pose_estimation_3d2d's T (to 1e-9).
# Usage: check_install.sh BUILD_DIR SOURCE_DIR PYTHON
set -euo pipefail
build="$1" source="$2" python="$3"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
cmake -S "$source/tests/install/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/consumer" -j2 >/dev/null

img="$source/data/images"
pair=("$img/1.png" "$img/2.png" "$img/1_depth.png" "$img/2_depth.png")
"$work/consumer/two_view_consumer" "${pair[@]}" "$img/camera.yaml" >"$work/consumer.txt"
"$prefix/bin/pose_estimation_3d2d" "${pair[@]}" --camera "$img/camera.yaml" \
  --json "$work/cli.json" >/dev/null
PYTHONPATH="$prefix/lib/python3/dist-packages" "$python" - "$work" "$img" <<'PY'
import json, sys
import cv2, numpy as np, pnpba
work, img = sys.argv[1], sys.argv[2]
assert pnpba.__file__.startswith(work), pnpba.__file__  # the installed module, not the build's
cli = np.array(json.load(open(f"{work}/cli.json"))["T"])
consumer = np.loadtxt(f"{work}/consumer.txt").reshape(4, 4)
r = pnpba.estimate_two_view(cv2.imread(f"{img}/1.png"),
                            cv2.imread(f"{img}/1_depth.png", cv2.IMREAD_UNCHANGED),
                            cv2.imread(f"{img}/2.png"),
                            cv2.imread(f"{img}/2_depth.png", cv2.IMREAD_UNCHANGED),
                            camera=pnpba.Camera.from_yaml(f"{img}/camera.yaml"))
assert np.abs(consumer - cli).max() < 1e-9, (consumer, cli)
assert np.abs(r.T - cli).max() < 1e-9, (r.T, cli)
print("install: consumer, Python and CLI agree on T")
PY

# The installed pnpba-batch runs the installed package (no PYTHONPATH): the same T as the CLI.
printf 'id\trgb1\tdepth1\trgb2\tdepth2\np\t%s\t%s\t%s\t%s\n' "${pair[0]}" "${pair[2]}" \
  "${pair[1]}" "${pair[3]}" >"$work/pairs.tsv"
env -u PYTHONPATH "$prefix/bin/pnpba-batch" "$work/pairs.tsv" --output "$work/batch.jsonl" \
  --camera "$img/camera.yaml" --quiet 2>/dev/null
"$python" - "$work" <<'PY'
import json, sys
import numpy as np
work = sys.argv[1]
batch = json.loads(open(f"{work}/batch.jsonl").readline())
cli = json.load(open(f"{work}/cli.json"))
assert np.abs(np.array(batch["T"]) - np.array(cli["T"])).max() < 1e-9, (batch["T"], cli["T"])
print("install: pnpba-batch agrees with the CLI")
PY

# Its --help is the text the build kept, installed beside the package: argparse's at 80 columns.
env -u PYTHONPATH -u COLUMNS "$prefix/bin/pnpba-batch" --help >"$work/help.txt"
cmp "$work/help.txt" <(env -u COLUMNS PYTHONPATH="$build/python" "$python" -m pnpba.batch --help)
ls "$prefix"/lib/python3/dist-packages/pnpba/batch_help_78.txt >/dev/null
echo "install: pnpba-batch --help is argparse's"
