#!/usr/bin/env python3
"""Start-up time of every tool (`TOOL --help`, pnpba-batch's too) and of `import pnpba` (and its
first use, which loads the extension), median of N runs, wall
clock from process start to exit, next to the number of shared libraries the loader maps; and a
whole run of pose_estimation_3d2d on the project's pair (data/images/, PNG), with the libraries
mapped while it runs (its plugins included).

    python3 bench/startup_bench.py [--build build] [--runs 15] [--json FILE]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

TOOLS = ["pose_estimation_3d2d", "evaluate_tum", "direct_ba", "render_synthetic",
         "bundle_adjust_pairs", "bundle_adjust_bal", "bal_synthetic"]


def median_ms(command, runs, env=None):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                       check=True)
        times.append((time.perf_counter() - start) * 1000.0)
    return statistics.median(times)


def linked_libraries(path):
    env = dict(os.environ, LD_TRACE_LOADED_OBJECTS="1")
    out = subprocess.run([path], stdout=subprocess.PIPE, env=env, check=True).stdout.decode()
    return sum(1 for line in out.splitlines() if ".so" in line)


def mapped_during(command):
    env = dict(os.environ, LD_DEBUG="files")
    err = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env,
                         check=True).stderr.decode(errors="replace")
    # At exit the loader finalises every object still mapped, plugins included ("calling fini"
    # lines; the pipeline silences stderr while a plugin loads, so its "file=" lines are lost).
    names = set()
    for line in err.splitlines():
        if "calling fini:" in line:
            names.add(line.split("calling fini:")[1].split()[0])
    return len(names)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="the build folder")
    parser.add_argument("--runs", type=int, default=15)
    parser.add_argument("--json", help="write {\"tools\": [...], \"python_import_ms\": ..., "
                                       "\"pair\": {...}}")
    args = parser.parse_args()
    rows = []
    for tool in TOOLS:
        path = os.path.join(args.build, "apps", tool)
        if not os.path.exists(path):
            sys.exit(f"startup_bench: {path}: not built")
        rows.append({"tool": tool, "help_ms": median_ms([path, "--help"], args.runs),
                     "libraries": linked_libraries(path)})
    images = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "images")
    pair = [os.path.join(args.build, "apps", "pose_estimation_3d2d")] + [
        os.path.join(images, f) for f in ("1.png", "2.png", "1_depth.png", "2_depth.png")] + [
        "--camera", os.path.join(images, "camera.yaml")]
    pair_row = {"wall_ms": median_ms(pair, args.runs), "libraries": mapped_during(pair)}
    python = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
    env = dict(os.environ, PYTHONPATH=os.path.join(args.build, "python"))
    interpreter_ms = median_ms([python, "-c", "pass"], args.runs, env)
    with_import_ms = median_ms([python, "-c", "import pnpba"], args.runs, env)
    # The extension loads on first use (pnpba/__init__.py): what a first call pays beyond that.
    first_use_ms = median_ms([python, "-c", "import pnpba; pnpba.Camera"], args.runs, env)
    # The floor under pnpba-batch --help where Python answers it (a width other than the kept
    # help's): an empty argparse parser's, in an interpreter without site as pnpba-batch starts.
    argparse_ms = median_ms([python, "-S", "-c", "import argparse; "
                             "argparse.ArgumentParser().parse_args(['--help'])"], args.runs, env)
    batch = os.path.join(args.build, "python", "pnpba-batch")
    if os.path.exists(batch):
        rows.append({"tool": "pnpba-batch", "help_ms": median_ms([batch, "--help"], args.runs),
                     "libraries": None})
    print(f"{'tool':<22} {'--help':>9} {'libraries':>10}")
    for r in rows:
        libraries = "(sh)" if r["libraries"] is None else r["libraries"]
        print(f"{r['tool']:<22} {r['help_ms']:7.1f} ms {libraries:>10}")
    print(f"(an empty argparse parser's --help in python3 -S: {argparse_ms:.1f} ms)")
    print(f"import pnpba: {with_import_ms - interpreter_ms:.1f} ms beyond the interpreter's own "
          f"{interpreter_ms:.1f} ms; its first use (the extension loaded) "
          f"{first_use_ms - interpreter_ms:.1f} ms")
    print(f"pose_estimation_3d2d on data/images: {pair_row['wall_ms']:.1f} ms, "
          f"{pair_row['libraries']} libraries mapped")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"tools": rows, "python_interpreter_ms": interpreter_ms,
                       "python_import_ms": with_import_ms - interpreter_ms,
                       "python_first_use_ms": first_use_ms - interpreter_ms,
                       "argparse_help_ms": argparse_ms, "pair": pair_row},
                      f, indent=2)


if __name__ == "__main__":
    main()
