#!/usr/bin/env python3
"""One pose_estimation_3d2d process per pair, as a user who calls the tool from a script: per set,
p50 / p95 / max of the in-process time (`--json`'s `timings_ms.total`) and of the wall clock
from start to exit. With --anchor, a second build runs each pair right after the first, so the
two are compared pair by pair in one run (the median of the paired differences is what the
machine's drift leaves alone).

    python3 bench/cli_pair_bench.py --shared ../shared/data [--build build]
        [--anchor OTHER/pose_estimation_3d2d] [--sets fr1_desk,cabinet] [--rounds 2] [--pairs N]
        [--json FILE]

Sets: fr1_desk (the shared TUM fr1_desk frames, pairs (i, i+k), k = 1..8: 36 pairs) and
cabinet (the fr3_cabinet key frames, (i, i+1), (i, i+3), (i, i+5): 78 pairs).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")


def fr1_pairs(shared):
    folder = os.path.join(shared, "tum_fr1_desk")
    rows = [line.split() for line in open(os.path.join(folder, "associate.txt"))
            if line.strip() and not line.startswith("#")]
    camera = os.path.join(ROOT, "data", "cameras", "tum_fr1.yaml")
    for i in range(len(rows)):
        for j in range(i + 1, min(i + 9, len(rows))):
            yield [os.path.join(folder, rows[i][1]), os.path.join(folder, rows[j][1]),
                   os.path.join(folder, rows[i][3]), os.path.join(folder, rows[j][3]),
                   "--camera", camera]


def cabinet_pairs(shared):
    folder = os.path.join(shared, "tum_fr3_cabinet_keyframes")
    frames = sorted(f[:-4] for f in os.listdir(os.path.join(folder, "rgb")) if f.endswith(".jpg"))
    camera = os.path.join(ROOT, "data", "cameras", "tum_fr3.yaml")
    for i in range(len(frames)):
        for k in (1, 3, 5):
            if i + k < len(frames):
                a, b = frames[i], frames[i + k]
                yield [os.path.join(folder, "rgb", a + ".jpg"),
                       os.path.join(folder, "rgb", b + ".jpg"),
                       os.path.join(folder, "depth", a + ".png"),
                       os.path.join(folder, "depth", b + ".png"), "--camera", camera]


SETS = {"fr1_desk": fr1_pairs, "cabinet": cabinet_pairs}
FOLDERS = {"fr1_desk": "tum_fr1_desk", "cabinet": "tum_fr3_cabinet_keyframes"}


def run_once(tool, pair, json_path):
    """(in-process ms, wall ms) of one run."""
    if os.path.exists(json_path):
        os.remove(json_path)  # a run that writes none must not be read as the last one's
    start = time.perf_counter()
    done = subprocess.run([tool] + pair + ["--json", json_path], stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
    wall = (time.perf_counter() - start) * 1000.0
    # 1: no pose, still timed and written.
    if done.returncode not in (0, 1) or not os.path.exists(json_path):
        last = done.stderr.strip().splitlines()[-1:] or ["no message"]
        sys.exit(f"cli_pair_bench: {tool} {pair[0]} ...: exit {done.returncode}: {last[0]}")
    with open(json_path) as f:
        return json.load(f)["timings_ms"]["total"], wall


def percentile(values, q):
    """The value at the rounded rank q (n - 1), as bench/percentile.h takes the C++ benches'."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * (len(ordered) - 1) + 0.5))]


def summary(values):
    return {"p50_ms": percentile(values, 0.5), "p95_ms": percentile(values, 0.95),
            "max_ms": max(values)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shared", required=True, help="the shared data folder")
    parser.add_argument("--build", default="build", help="the build folder")
    parser.add_argument("--anchor", help="another pose_estimation_3d2d to run beside it")
    parser.add_argument("--sets", default="fr1_desk,cabinet")
    parser.add_argument("--rounds", type=int, default=2, help="times over every pair")
    parser.add_argument("--pairs", type=int, default=0, help="the first N pairs of a set (0: all)")
    parser.add_argument("--json", help="write {\"sets\": [...]}")
    args = parser.parse_args()
    if args.rounds < 1 or args.pairs < 0:
        sys.exit("cli_pair_bench: --rounds must be >= 1 and --pairs >= 0")
    if args.json and not os.path.isdir(os.path.dirname(os.path.abspath(args.json))):
        sys.exit(f"cli_pair_bench: {args.json}: folder does not exist")
    tool = os.path.join(args.build, "apps", "pose_estimation_3d2d")
    tools = [("build", tool)] + ([("anchor", args.anchor)] if args.anchor else [])
    for _, path in tools:
        if not os.access(path, os.X_OK):
            sys.exit(f"cli_pair_bench: {path}: not an executable")
    names = args.sets.split(",")
    for name in names:  # every set checked before the first runs
        if name not in SETS:
            sys.exit(f"cli_pair_bench: unknown set '{name}' (fr1_desk, cabinet)")
        folder = os.path.join(args.shared, FOLDERS[name])
        if not os.path.isdir(folder):
            sys.exit(f"cli_pair_bench: {folder}: no such folder (--shared)")
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        json_path = os.path.join(tmp, "pair.json")
        for name in names:
            pairs = list(SETS[name](args.shared))
            if args.pairs > 0:
                pairs = pairs[:args.pairs]
            times = {label: ([], []) for label, _ in tools}
            for _ in range(args.rounds):
                for index, pair in enumerate(pairs):
                    # Every other pair the anchor first: neither build always runs warmer.
                    for label, path in (tools if index % 2 == 0 else tools[::-1]):
                        inside, wall = run_once(path, pair, json_path)
                        times[label][0].append(inside)
                        times[label][1].append(wall)
            row = {"name": name, "runs": len(pairs) * args.rounds}
            for label, (inside, wall) in times.items():
                row[label] = {"in_process": summary(inside), "wall": summary(wall)}
            if args.anchor:
                row["paired_median_ms"] = {
                    kind: statistics.median(b - a for a, b in zip(times["anchor"][k],
                                                                  times["build"][k]))
                    for k, kind in enumerate(("in_process", "wall"))}
            out.append(row)
            print(f"{name}: {row['runs']} runs")
            for label, _ in tools:
                for kind in ("in_process", "wall"):
                    s = row[label][kind]
                    print(f"  {label:<7} {kind:<11} p50 {s['p50_ms']:6.1f}  p95 {s['p95_ms']:6.1f}"
                          f"  max {s['max_ms']:6.1f} ms")
            if args.anchor:
                d = row["paired_median_ms"]
                print(f"  build - anchor, median per pair: in process {d['in_process']:+.2f} ms,"
                      f" wall {d['wall']:+.2f} ms")
    if args.json:
        text = json.dumps({"sets": out}, indent=2) + "\n"
        with open(args.json, "w") as f:  # one write, after every run
            f.write(text)


if __name__ == "__main__":
    main()
