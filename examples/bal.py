#!/usr/bin/env python3
"""Bundle-adjusts a BAL problem with pnpba from Python, with a progress bar (tqdm when
installed, plain lines otherwise), and writes the result.

    PYTHONPATH=build/python python3 examples/bal.py ../shared/data/bal/problem-49-7776-pre.txt \
        --output solved.txt --ply solved.ply
"""
import argparse
import sys

import pnpba

try:
    from tqdm import tqdm
except ImportError:
    tqdm = None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("problem", help="BAL problem file")
    parser.add_argument("--iterations", type=int, default=50)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--solver", default="pnpba",
                        help="pnpba, ceres-dense_schur, ceres-sparse_schur, "
                             "ceres-iterative_schur or native")
    parser.add_argument("--output", help="write the solved problem (BAL format)")
    parser.add_argument("--ply", help="write cameras and points as PLY")
    args = parser.parse_args()

    try:
        problem = pnpba.read_bal(args.problem)
    except pnpba.Error as e:
        sys.exit(f"bal.py: {e}")
    print(problem)

    bar = tqdm(total=args.iterations, unit="it") if tqdm else None

    def progress(row):
        if bar is not None:
            if row["iteration"] > 0:
                bar.update(1)
            bar.set_postfix(cost=f"{row['cost']:.6g}")
        else:
            print(f"iteration {row['iteration']:3d}  cost {row['cost']:.6e}  "
                  f"time {row['time_s']:.3f} s", flush=True)

    summary = pnpba.solve_bal(problem, iterations=args.iterations, threads=args.threads,
                              solver=args.solver, callback=progress)
    if bar is not None:
        bar.close()
    print(f"cost {summary.initial_cost:.6e} -> {summary.final_cost:.6e} in {summary.iterations} "
          f"iterations, {summary.time_s:.3f} s ({summary.termination}); "
          f"RMS {summary.rms_px_initial:.3f} -> {summary.rms_px_final:.3f} px")
    if args.output:
        problem.write(args.output)
    if args.ply:
        problem.write_ply(args.ply)
    return 0 if summary.ok else 1


if __name__ == "__main__":
    sys.exit(main())
