#!/usr/bin/env python3
"""pnpba's bundle_adjust_bal against Ceres's own `bundle_adjuster` example program, as separate
processes, alternating, on the same BAL files and threads.

`bal_bench` compares against Ceres in-process, with bundle_adjuster's set-up rebuilt; this runs
the example program itself: Debian's ceres-solver-doc ships its source, which is built here
against the installed Ceres (downloaded with `apt-get download` when the package is not
installed; `--bundle-adjuster PATH` takes a binary built elsewhere).

Per problem and program, the median over repetitions of the time to first come within 0.1 % of
the converged cost (the lower of the two final costs), read from each program's own
per-iteration table: Ceres's cumulative time (its preprocessing included), pnpba's `--json`
per-iteration times (its set-up included). File reading is in neither.

    python3 bench/bundle_adjuster_side_by_side.py [--build build] [--threads 2]
        [--repetitions 3] [--cameras 300,3000] [--iterations 50] [--json FILE]
        [--bal ../shared/data/bal/problem-49-7776-pre.txt] [--bundle-adjuster PATH]
"""
import argparse
import glob
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

NEAR = 1e-3  # "within 0.1 %": cost <= converged * (1 + NEAR)
# One row of Ceres's per-iteration table: iter cost cost_change |gradient| |step| tr_ratio
# tr_radius ls_iter iter_time total_time.
CERES_ROW = re.compile(r"^\s*(\d+)\s+([-+0-9.e]+)\s+\S+\s+\S+\s+\S+\s+\S+\s+\S+\s+\d+\s+\S+\s+(\S+)\s*$")


def fail(message):
    print(f"bundle_adjuster_side_by_side: {message}", file=sys.stderr)
    sys.exit(1)


def example_sources(work):
    """Ceres's examples folder: the installed package's, else one extracted from its .deb."""
    installed = "/usr/share/doc/ceres-solver-doc/examples"
    if os.path.isfile(os.path.join(installed, "bundle_adjuster.cc")):
        return installed
    print("downloading ceres-solver-doc for the bundle_adjuster example ...", file=sys.stderr)
    if subprocess.run(["apt-get", "download", "ceres-solver-doc"], cwd=work,
                      stdout=subprocess.DEVNULL).returncode != 0:
        fail("cannot download ceres-solver-doc (apt-get download); pass --bundle-adjuster PATH")
    debs = glob.glob(os.path.join(work, "ceres-solver-doc_*.deb"))
    if not debs:
        fail("apt-get download left no ceres-solver-doc package")
    subprocess.run(["dpkg", "-x", debs[0], os.path.join(work, "doc")], check=True)
    return os.path.join(work, "doc/usr/share/doc/ceres-solver-doc/examples")


def build_bundle_adjuster(output):
    with tempfile.TemporaryDirectory() as work:
        src = example_sources(work)
        print(f"building Ceres's bundle_adjuster from {src} ...", file=sys.stderr)
        command = ["g++", "-O3", "-DNDEBUG", "-std=c++17", "-I", src, "-I/usr/include/eigen3",
                   os.path.join(src, "bundle_adjuster.cc"), os.path.join(src, "bal_problem.cc"),
                   "-o", output + ".part", "-lceres", "-lgflags", "-lglog", "-lpthread"]
        if subprocess.run(command).returncode != 0:
            fail("building bundle_adjuster failed (needs libceres-dev, libgflags-dev, "
                 "libgoogle-glog-dev)")
    os.replace(output + ".part", output)


def run_ceres(binary, problem, threads, iterations, solver):
    out = subprocess.run([binary, f"--input={problem}", f"--linear_solver={solver}",
                          f"--num_threads={threads}", f"--num_iterations={iterations}"],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if out.returncode != 0:
        fail(f"{problem}: Ceres's bundle_adjuster failed:\n{out.stdout[-2000:]}")
    table = []
    for line in out.stdout.splitlines():
        m = CERES_ROW.match(line)
        if m:
            table.append((float(m.group(3)), float(m.group(2))))
    if not table:
        fail(f"{problem}: no per-iteration table in bundle_adjuster's output")
    return table


def run_pnpba(binary, problem, threads, iterations):
    with tempfile.TemporaryDirectory() as work:
        summary = os.path.join(work, "summary.json")
        out = subprocess.run([binary, problem, "--normalize", "--threads", str(threads),
                              "--iterations", str(iterations), "--json", summary],
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if out.returncode != 0:
            fail(f"{problem}: bundle_adjust_bal failed:\n{out.stdout[-2000:]}")
        with open(summary) as f:
            rows = json.load(f)["per_iteration"]
    return [(r["time_s"], r["cost"]) for r in rows]


def write_output(path, text):
    """A regular file (or a new path, or a link's target) through a temporary file and a rename;
    anything else (a pipe, a device, /dev/stdout) written in place."""
    try:
        if os.path.exists(path) and not os.path.isfile(path):
            with open(path, "w") as f:
                f.write(text)
            return
        target = os.path.realpath(path)
        tmp = f"{target}.tmp{os.getpid()}"
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, target)
    except OSError as e:
        fail(f"{path}: cannot write: {e.strerror}")


def first_time_below(table, cost):
    for t, c in table:
        if c <= cost:
            return t
    return None


def compare(name, problem, cameras, args, ceres_binary, pnpba_binary):
    solver = "dense_schur" if cameras <= 100 else "sparse_schur"
    ceres_runs, pnpba_runs = [], []
    for k in range(args.repetitions):
        print(f"{name}: repetition {k + 1} of {args.repetitions}", file=sys.stderr)
        ceres_runs.append(run_ceres(ceres_binary, problem, args.threads, args.iterations, solver))
        pnpba_runs.append(run_pnpba(pnpba_binary, problem, args.threads, args.iterations))
    ceres_final = statistics.median(t[-1][1] for t in ceres_runs)
    pnpba_final = statistics.median(t[-1][1] for t in pnpba_runs)
    near = min(ceres_final, pnpba_final) * (1 + NEAR)
    ceres_near = statistics.median(first_time_below(t, near) or float("inf") for t in ceres_runs)
    pnpba_near = statistics.median(first_time_below(t, near) or float("inf") for t in pnpba_runs)
    if ceres_near == float("inf") or pnpba_near == float("inf"):
        fail(f"{name}: a program never came within 0.1 % of the converged cost "
             "(raise --iterations)")
    return {"problem": name, "cameras": cameras, "ceres_linear_solver": solver,
            "threads": args.threads, "ceres_final_cost": ceres_final,
            "pnpba_final_cost": pnpba_final, "ceres_s_within_0p1_percent": ceres_near,
            "pnpba_s_within_0p1_percent": pnpba_near, "ratio": pnpba_near / ceres_near}


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default=os.path.join(root, "build"), help="the build folder")
    parser.add_argument("--bundle-adjuster", help="Ceres's bundle_adjuster (default: build it)")
    parser.add_argument("--bal", default=os.path.join(root, "..", "shared", "data", "bal",
                                                      "problem-49-7776-pre.txt"),
                        help="a BAL problem from a file (Ladybug-49; '' for none)")
    parser.add_argument("--cameras", default="300,3000", help="generated problem sizes")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repetitions", type=int, default=3)
    parser.add_argument("--iterations", type=int, default=50, help="at most, both programs")
    parser.add_argument("--json", help="write the rows as a JSON list")
    args = parser.parse_args()
    if args.threads < 1 or args.repetitions < 1 or args.iterations < 1:
        fail("--threads, --repetitions and --iterations must be >= 1")
    apps = os.path.join(args.build, "apps")
    pnpba_binary = os.path.join(apps, "bundle_adjust_bal")
    generator = os.path.join(apps, "bal_synthetic")
    for tool in (pnpba_binary, generator):
        if not os.access(tool, os.X_OK):
            fail(f"{tool}: not built (scripts/build.sh)")
    try:
        sizes = [int(c) for c in args.cameras.split(",") if c.strip()]
    except ValueError:
        fail(f"--cameras: '{args.cameras}' is not a comma list of camera counts")
    if any(c < 2 for c in sizes):
        fail("--cameras: sizes must be >= 2")
    bal_cameras = 0
    if args.bal:
        try:
            with open(args.bal) as f:
                bal_cameras = int(f.readline().split()[0])
        except (OSError, ValueError, IndexError) as e:
            reason = e.strerror if isinstance(e, OSError) else "no camera count on its first line"
            fail(f"{args.bal}: not a readable BAL file ({reason})")
    ceres_binary = args.bundle_adjuster or os.path.join(args.build, "bench",
                                                        "ceres_bundle_adjuster")
    if not os.access(ceres_binary, os.X_OK):
        if args.bundle_adjuster:
            fail(f"{ceres_binary}: not an executable")
        build_bundle_adjuster(ceres_binary)

    rows = []
    with tempfile.TemporaryDirectory() as work:
        problems = []
        if args.bal:
            problems.append((os.path.basename(args.bal), args.bal, bal_cameras))
        for c in sizes:
            path = os.path.join(work, f"generated-{c}.txt")
            subprocess.run([generator, "--cameras", str(c), "--points", str(60 * c),
                            "--observations-per-point", "5", "--output", path],
                           stdout=subprocess.DEVNULL, check=True)
            problems.append((f"generated-{c}", path, c))
        print(f"{'problem':28} {'cams':>5} {'ceres':>13} {'within 0.1 %: ceres':>20} "
              f"{'pnpba':>8} {'ratio':>6}   final cost: ceres, pnpba")
        for name, path, cameras in problems:
            r = compare(name, path, cameras, args, ceres_binary, pnpba_binary)
            rows.append(r)
            print(f"{name:28} {cameras:5d} {r['ceres_linear_solver']:>13} "
                  f"{r['ceres_s_within_0p1_percent']:18.3f} s "
                  f"{r['pnpba_s_within_0p1_percent']:6.3f} s {r['ratio']:6.3f}   "
                  f"{r['ceres_final_cost']:.6e}, {r['pnpba_final_cost']:.6e}", flush=True)
    if args.json:
        write_output(args.json, json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
