#!/usr/bin/env python3
"""batch_bench: throughput of pnpba-batch (pairs/s) and its per-task overhead.

    PYTHONPATH=build/python python3 bench/batch_bench.py [--shared ../shared/data] [--repeats 3]
        [--json FILE]

Sets: the shared TUM fr1_desk pairs (--pairs within:8, 36 pairs) and rendered wide-baseline
pairs (the closed rich room, 10-30 degrees, 0.25-1 m, 2 seeds; written by render_synthetic). Engines: a
local cluster with 1 and 2 threads, and a `dask scheduler` with two `dask worker` processes
(one thread each) over TCP on 127.0.0.1. Per run: wall time of the whole job (the median of
--repeats), its fixed start-up (interpreter, Dask, cluster: a one-pair job), pairs/s once
running ((wall - start-up) / pairs), the estimate's own median in-process time
(timings_ms.total), and what a task costs beyond it: that time x threads minus the estimate
(reading the images, cached per worker, and Dask). Each set lists its pairs 5 times.
"""
import argparse
import json
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)


def fr1_table(folder, tmp, copies):
    """The fr1_desk pairs within 8 frames, each listed `copies` times under its own id."""
    import pnpba

    frames = pnpba.tum_frames(folder)
    rows = ["id\trgb1\tdepth1\trgb2\tdepth2"]
    for c in range(copies):
        for i in range(len(frames)):
            for j in range(i + 1, min(i + 8, len(frames) - 1) + 1):
                a, b = frames[i], frames[j]
                rows.append(f"{c}-{i}-{j}\t{a['rgb']}\t{a['depth']}\t{b['rgb']}\t{b['depth']}")
    table = os.path.join(tmp, "fr1.tsv")
    with open(table, "w") as f:
        f.write("\n".join(rows) + "\n")
    return table


def render_set(folder, renderer, copies):
    rows = ["id\trgb1\tdepth1\trgb2\tdepth2"]
    n = 0
    for deg in (10, 20, 30):
        for metres in (0.25, 0.5, 1.0):
            for seed in (1, 2):
                out = os.path.join(folder, f"r{n}")
                subprocess.run([renderer, "--output", out, "--scene", "room", "--seed", str(seed),
                                "--rotation-deg", str(deg), "--translation-m", str(metres)],
                               check=True, capture_output=True)
                for c in range(copies):
                    rows.append("\t".join([f"r{n}-{c}"] + [os.path.join(out, f) for f in
                                                          ("1.png", "1_depth.png", "2.png",
                                                           "2_depth.png")]))
                n += 1
    table = os.path.join(folder, "pairs.tsv")
    with open(table, "w") as f:
        f.write("\n".join(rows) + "\n")
    return table, os.path.join(folder, "r0", "camera.yaml")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def start_cluster():
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
                               "127.0.0.1", "--port", str(port), "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    for _ in range(2):
        procs.append(subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_worker",
                                       address, "--nthreads", "1", "--no-dashboard"],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
    from distributed import Client

    with Client(address, timeout="30s") as c:
        c.wait_for_workers(2, timeout=60)
    return address, procs


def run(argv, output):
    if os.path.exists(output):
        os.remove(output)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "pnpba.batch", *argv, "--output", output, "--quiet"],
                   check=True, capture_output=True)
    wall = time.perf_counter() - start
    records = [json.loads(line) for line in open(output)]
    inproc = statistics.median(r["timings_ms"]["total"] for r in records if "timings_ms" in r)
    return wall, len(records), inproc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--shared", default=os.path.join(SOURCE, "..", "shared", "data"))
    ap.add_argument("--renderer", default=os.path.join(SOURCE, "build", "apps", "render_synthetic"))
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="batch_bench")
    sets = []
    fr1 = os.path.join(args.shared, "tum_fr1_desk")
    if os.path.isdir(fr1):
        sets.append(("fr1_desk within:8 x5", [fr1_table(fr1, tmp, 5)]))
    table, camera = render_set(tmp, args.renderer, copies=5)
    sets.append(("rendered room x5", [table, "--camera", camera]))
    # The job's fixed cost (interpreter, Dask, the cluster's start): one pair.
    one = os.path.join(tmp, "one.tsv")
    with open(table) as f:
        lines = f.read().splitlines()
    with open(one, "w") as f:
        f.write("\n".join(lines[:2]) + "\n")
    address, procs = start_cluster()
    rows = []
    try:
        engines = [("local, 1 thread", ["--workers", "1"], 1),
                   ("local, 2 threads", ["--workers", "2"], 2),
                   ("scheduler + 2 workers (TCP)", ["--scheduler", address], 2),
                   ("... with --ship-images", ["--scheduler", address, "--ship-images"], 2)]
        startup = {}
        for engine, extra, _ in engines:
            startup[engine] = statistics.median(
                run([one, "--camera", camera] + extra, os.path.join(tmp, "out.jsonl"))[0]
                for _ in range(args.repeats))
        for name, argv in sets:
            for engine, extra, threads in engines:
                runs = [run(argv + extra, os.path.join(tmp, "out.jsonl"))
                        for _ in range(args.repeats)]
                wall = statistics.median(r[0] for r in runs)
                pairs, inproc = runs[0][1], runs[0][2]
                steady = (wall - startup[engine]) / pairs  # s per pair once running
                row = {"set": name, "engine": engine, "pairs": pairs, "wall_s": wall,
                       "startup_s": startup[engine], "pairs_per_s": 1 / steady,
                       "estimate_ms": inproc, "beyond_ms": steady * threads * 1000 - inproc}
                rows.append(row)
                print("%-20s %-28s %4d pairs %6.2f s (start %4.2f s) %6.1f pairs/s  estimate "
                      "%5.1f ms  beyond it %5.1f ms/task" % (
                          name, engine, pairs, wall, startup[engine], row["pairs_per_s"], inproc,
                          row["beyond_ms"]), flush=True)
    finally:
        for p in procs:
            p.terminate()
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"runs": rows}, f, indent=2)


if __name__ == "__main__":
    main()
