#!/usr/bin/env python3
"""Start-up time of every tool (`TOOL --help`) and of `import pnpba`, median of N runs, wall
clock from process start to exit, next to the number of shared libraries the loader maps.

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


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="the build folder")
    parser.add_argument("--runs", type=int, default=15)
    parser.add_argument("--json", help="write {\"tools\": [...], \"python_import_ms\": ...}")
    args = parser.parse_args()
    rows = []
    for tool in TOOLS:
        path = os.path.join(args.build, "apps", tool)
        if not os.path.exists(path):
            sys.exit(f"startup_bench: {path}: not built")
        rows.append({"tool": tool, "help_ms": median_ms([path, "--help"], args.runs),
                     "libraries": linked_libraries(path)})
    python = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
    env = dict(os.environ, PYTHONPATH=os.path.join(args.build, "python"))
    interpreter_ms = median_ms([python, "-c", "pass"], args.runs, env)
    with_import_ms = median_ms([python, "-c", "import pnpba"], args.runs, env)
    print(f"{'tool':<22} {'--help':>9} {'libraries':>10}")
    for r in rows:
        print(f"{r['tool']:<22} {r['help_ms']:7.1f} ms {r['libraries']:>10}")
    print(f"import pnpba: {with_import_ms - interpreter_ms:.1f} ms beyond the interpreter's own "
          f"{interpreter_ms:.1f} ms")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"tools": rows, "python_interpreter_ms": interpreter_ms,
                       "python_import_ms": with_import_ms - interpreter_ms}, f, indent=2)


if __name__ == "__main__":
    main()
