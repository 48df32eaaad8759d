"""pnpba.batch: the two-view pose over whole datasets of pairs, on Dask.

    pnpba-batch INPUT --output RESULTS.jsonl [--pairs consecutive|within:K] [--camera F.yaml]
                [--workers N] [--scheduler tcp://HOST:PORT] [--ship-images]
                [--g2o F.g2o] [--trajectory F.txt] [--check-chain F.tsv] [--csv F.csv]
                [two-view options]

INPUT is a pair table (TSV with the header ``id rgb1 depth1 rgb2 depth2`` and optional
per-row camera columns, ``camera`` (a YAML path) or ``fx fy cx cy [depth_scale]``; paths
relative to the table) or a TUM folder (pairs by ``--pairs``, frames
by evaluate_tum's association rules). Each pair is one Dask task; without ``--scheduler`` a
local cluster of threads runs them (the estimator releases the GIL), with it an existing
cluster does. Results are appended to RESULTS.jsonl one whole line per pair as they arrive:
the pair's ``id``, its four image paths and the fields of ``pose_estimation_3d2d --json``; a
pair that cannot be read has ``"ok": false`` and ``"error"``. Rerunning the same command
resumes: pairs whose ids are in the file are skipped. The pose graph (``--g2o``), the chained
trajectory (``--trajectory``), the chain check (``--check-chain``) and the CSV summary
(``--csv``) are written from the whole file at the end. See docs/batch.md.
"""
import argparse
import functools
import math
import os
import sys
import time

from pnpba.batch_help import help_width

# csv, json and shutil (argparse's terminal width) are imported where used: `pnpba-batch --help`
# needs none of them, and they were 4 ms of its 27.

# Two-view options: CLI flag -> (estimate_two_view keyword, type). Defaults are the library's.
TWO_VIEW_OPTIONS = {
    "--preset": ("preset", str),
    "--features": ("features", int),
    "--max-feature-pixels": ("max_feature_pixels", int),
    "--detector": ("detector", str),
    "--match-filter": ("match_filter", str),
    "--ransac-threshold": ("ransac_threshold", float),
    "--ba": ("ba", str),
    "--solver": ("solver", str),
    "--depth-path": ("depth_path", str),
    "--max-sigma-deg": ("max_sigma_deg", float),
    "--max-sigma-cm": ("max_sigma_cm", float),
    "--focal-sigma": ("focal_sigma", float),
    "--principal-point-sigma": ("principal_point_sigma", float),
    "--depth-scale-sigma": ("depth_scale_sigma", float),
    "--motion-sigma": ("motion_sigma", float),
    "--motion-cap-deg": ("motion_cap_deg", float),
    "--motion-cap-cm": ("motion_cap_cm", float),
    "--time-budget-ms": ("time_budget_ms", float),
}
PATH_FIELDS = ("rgb1", "depth1", "rgb2", "depth2")
INTRINSICS = ("fx", "fy", "cx", "cy", "depth_scale")  # optional per-row camera columns


class InputError(Exception):
    """Bad input: reported as one line naming the file, exit 2."""


# ---------------------------------------------------------------------------------------------
# Pairs


def read_pair_table(path):
    """Pairs of a TSV table: header ``id rgb1 depth1 rgb2 depth2 [camera]``; empty or '-' depth2:
    none. Relative paths are relative to the table's folder."""
    import csv

    folder = os.path.dirname(os.path.abspath(path))
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f, delimiter="\t"))
    except OSError as e:
        raise InputError(f"{path}: {e.strerror}")
    if not rows:
        raise InputError(f"{path}: empty pair table (expected a header 'id rgb1 depth1 rgb2 depth2')")
    header = [h.strip() for h in rows[0]]
    missing = [h for h in ("id",) + PATH_FIELDS if h not in header]
    if missing:
        raise InputError(f"{path}:1: header lacks {', '.join(missing)} "
                         "(expected 'id rgb1 depth1 rgb2 depth2 [camera]', tab-separated)")
    pairs, seen = [], set()
    for n, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise InputError(f"{path}:{n}: {len(row)} columns, the header has {len(header)}")
        cells = dict(zip(header, (c.strip() for c in row)))
        if not cells["id"] or cells["id"] in seen:
            raise InputError(f"{path}:{n}: id '{cells['id']}' is empty or repeated")
        seen.add(cells["id"])
        pair = {"id": cells["id"]}
        for field in PATH_FIELDS:
            value = cells[field]
            if field == "depth2" and value in ("", "-"):
                pair[field] = None
            elif not value:
                raise InputError(f"{path}:{n}: {field} is empty")
            else:
                pair[field] = os.path.normpath(os.path.join(folder, value))
        camera = cells.get("camera", "")
        if camera:
            pair["camera"] = os.path.normpath(os.path.join(folder, camera))
        elif any(cells.get(k, "") for k in INTRINSICS):
            pair["intrinsics"] = _intrinsics(path, n, cells)
        pair["frame1"], pair["frame2"] = pair["rgb1"], pair["rgb2"]
        pairs.append(pair)
    return pairs


def _intrinsics(path, n, cells):
    """A row's fx fy cx cy [depth_scale] as floats (depth_scale: 5000, TUM's, when absent)."""
    values = []
    for k in INTRINSICS:
        text = cells.get(k, "")
        if not text and k == "depth_scale":
            values.append(5000.0)
            continue
        try:
            v = float(text)
        except ValueError:
            raise InputError(f"{path}:{n}: {k} '{text}' is not a number")
        if not math.isfinite(v) or (k != "cx" and k != "cy" and v <= 0):
            raise InputError(f"{path}:{n}: {k} {text} must be finite" +
                             ("" if k in ("cx", "cy") else " and > 0"))
        values.append(v)
    return values


def parse_pairs_rule(text):
    """'consecutive' -> 1; 'within:K' -> K (K >= 1)."""
    if text == "consecutive":
        return 1
    if text.startswith("within:"):
        try:
            k = int(text[len("within:"):])
        except ValueError:
            k = 0
        if k >= 1:
            return k
    raise InputError(f"--pairs: expected 'consecutive' or 'within:K' with K >= 1, got '{text}'")


def tum_pairs(folder, max_gap):
    """Every pair (i, j), 1 <= j - i <= max_gap, of a TUM folder's frames (evaluate_tum's
    association rules); ids 'i-j' by frame index."""
    import pnpba

    try:
        frames = pnpba.tum_frames(folder)
    except pnpba.Error as e:
        raise InputError(str(e))
    if len(frames) < 2:
        raise InputError(f"{folder}: fewer than two frames with colour and depth")
    pairs = []
    for i in range(len(frames)):
        for j in range(i + 1, min(i + max_gap, len(frames) - 1) + 1):
            a, b = frames[i], frames[j]
            pairs.append({"id": f"{i}-{j}", "rgb1": a["rgb"], "depth1": a["depth"],
                          "rgb2": b["rgb"], "depth2": b["depth"], "frame1": i, "frame2": j,
                          "stamp1": a["rgb_stamp"], "stamp2": b["rgb_stamp"]})
    return pairs


# ---------------------------------------------------------------------------------------------
# The task (runs on a worker)


@functools.lru_cache(maxsize=64)
def _read_cached(path, size, mtime_ns, flags):
    """A decoded image, kept per worker process: with --pairs within:K every frame is in up to
    2K pairs, and decoding a 640x480 PNG pair costs about as much as estimating the pose. The
    key holds the file's size and time, so a changed file is read again. Read-only: the
    estimator never writes into its inputs."""
    import cv2

    image = cv2.imread(path, flags)
    if image is not None:
        image.setflags(write=False)
    return image


@functools.lru_cache(maxsize=64)
def _features_cached(path, size, mtime_ns, options):
    """A colour image's features (pnpba.describe_frame), kept per worker process beside the
    decoded image: a frame in several pairs is described once, and estimate_two_view given its
    features returns the same answer (an odometry pair's time falls by about a quarter).
    options: the pair's two-view options as sorted (name, value) items, whose feature options
    the features follow."""
    import cv2
    import pnpba

    image = _read_cached(path, size, mtime_ns, cv2.IMREAD_COLOR)
    return pnpba.describe_frame(image, **dict(options))


def _frame_features(path, data, options):
    """The features of a colour image read from its path (None for one shipped as bytes)."""
    if data is not None or not path:
        return None
    st = os.stat(path)
    return _features_cached(path, st.st_size, st.st_mtime_ns, tuple(sorted(options.items())))


def _decode(name, path, data, depth):
    import cv2
    import numpy as np

    flags = cv2.IMREAD_UNCHANGED if depth else cv2.IMREAD_COLOR
    if data is not None:
        image = cv2.imdecode(np.frombuffer(data, np.uint8), flags)
    elif not os.path.isfile(path):
        raise InputError(f"{path}: no such file ({name})")
    else:
        st = os.stat(path)
        image = _read_cached(path, st.st_size, st.st_mtime_ns, flags)
    if image is None:
        raise InputError(f"{path}: not a readable image ({name})")
    return image


def camera_from_spec(spec):
    """A camera YAML's path, ("tum", N) for a TUM freiburg camera, or None (TUM freiburg1)."""
    import pnpba

    if spec is None:
        return pnpba.tum_camera(1)
    if isinstance(spec, tuple):
        return pnpba.tum_camera(spec[1])
    return pnpba.Camera.from_yaml(spec)


def estimate_pair(pair, options, camera_path, images=None):
    """One pair's record: id, paths and the CLI's JSON fields, or ok false with the error."""
    import pnpba

    record = {"id": pair["id"], **{f: pair.get(f) for f in PATH_FIELDS}}
    try:
        images = images or {}
        loaded = {f: (_decode(f, pair[f], images.get(f), f.startswith("depth"))
                      if pair.get(f) else None) for f in PATH_FIELDS}
        if pair.get("intrinsics"):
            fx, fy, cx, cy, depth_scale = pair["intrinsics"]
            camera = pnpba.Camera(fx, fy, cx, cy, depth_scale=depth_scale)
        else:
            camera = camera_from_spec(pair.get("camera") or camera_path)
        r = pnpba.estimate_two_view(
            loaded["rgb1"], loaded["depth1"], loaded["rgb2"], loaded["depth2"], camera=camera,
            features1=_frame_features(pair["rgb1"], images.get("rgb1"), options),
            features2=_frame_features(pair["rgb2"], images.get("rgb2"), options), **options)
        import json

        record.update(json.loads(r.to_json()))
    except (InputError, pnpba.Error, ValueError, OSError) as e:
        record.update({"ok": False, "error": str(e)})
    return record


# ---------------------------------------------------------------------------------------------
# Results file: one whole line per pair, appended; resumable


def read_results(path):
    """Records of a results file; a trailing partial line (a crash mid-write) is cut off."""
    import json

    if not os.path.exists(path):
        return []
    with open(path, "rb") as f:
        data = f.read()
    end = data.rfind(b"\n") + 1
    if end < len(data) and os.path.isfile(path) and not os.path.islink(path):
        with open(path, "r+b") as f:
            f.truncate(end)
    records = []
    for n, line in enumerate(data[:end].splitlines(), start=1):
        if not line.strip():
            continue
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            raise InputError(f"{path}:{n}: not a JSON line (is this a pnpba-batch output?)")
    return records


class ResultsWriter:
    """Appends each record as one write() of one whole line (O_APPEND): a reader, a crash or
    Ctrl-C never sees half a record."""

    def __init__(self, path):
        self.fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)

    def append(self, record):
        import json

        data = (json.dumps(record, separators=(",", ":")) + "\n").encode()
        written = os.write(self.fd, data)
        if written != len(data):
            raise OSError(f"short write ({written} of {len(data)} bytes)")

    def close(self):
        os.close(self.fd)


# ---------------------------------------------------------------------------------------------
# Running


def make_parser(width):
    ap = argparse.ArgumentParser(
        prog="pnpba-batch",
        formatter_class=lambda prog: argparse.HelpFormatter(prog, width=width),
        description="The two-view pose over a whole dataset of pairs, on Dask (a local cluster "
                    "or an existing one). Resumable: rerun the same command to continue.")
    ap.add_argument("input", help="a pair table (TSV: id rgb1 depth1 rgb2 depth2, optionally "
                                  "camera or fx fy cx cy [depth_scale]) or a TUM folder")
    ap.add_argument("--output", required=True, help="results, JSON Lines (appended; resumed)")
    ap.add_argument("--pairs", default="consecutive",
                    help="TUM folder: 'consecutive' or 'within:K' (default: consecutive)")
    ap.add_argument("--camera", help="camera YAML for rows without their own (default: the TUM "
                                     "folder's camera.yaml, else the TUM freiburg1/2/3 camera "
                                     "its path names, else freiburg1)")
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                    help="local cluster threads (default: all cores)")
    ap.add_argument("--scheduler", help="tcp://HOST:PORT of an existing Dask scheduler")
    ap.add_argument("--ship-images", action="store_true",
                    help="send the image bytes with each task (clusters without a shared file "
                         "system)")
    ap.add_argument("--g2o", help="write the accepted poses as a g2o pose graph")
    ap.add_argument("--trajectory", help="TUM folder: chain consecutive pairs into a TUM "
                                         "trajectory")
    ap.add_argument("--check-chain", metavar="FILE",
                    help="TUM folder: test each pose two or more frames apart against the "
                         "consecutive pairs chained between its frames (chi-squared, 99.9 %%, "
                         "on their covariances), write the tests to FILE (TSV) and leave the "
                         "contradicted poses out of --g2o")
    ap.add_argument("--csv", help="write a CSV summary, one row per pair")
    ap.add_argument("--quiet", action="store_true", help="no progress bar")
    for flag, (key, kind) in TWO_VIEW_OPTIONS.items():
        ap.add_argument(flag, dest=key, type=kind, help=f"as pose_estimation_3d2d {flag}")
    ap.add_argument("--no-undistort", dest="undistort", action="store_false", default=None,
                    help="as pose_estimation_3d2d")
    ap.add_argument("--no-sift-retry", dest="retry_with_sift", action="store_false", default=None,
                    help="as pose_estimation_3d2d")
    ap.add_argument("--no-fuse-agreeing", dest="fuse_agreeing", action="store_false",
                    default=None, help="as pose_estimation_3d2d --fuse-agreeing false")
    return ap


def help_text(width):
    """argparse's --help for pnpba-batch at this width (batch_help keeps it at build time)."""
    return make_parser(width).format_help()


def parse_args(argv):
    ap = make_parser(help_width())
    args = ap.parse_args(argv)
    if args.workers < 1:
        ap.error("--workers must be >= 1")
    return args


def load_pairs(args):
    if os.path.isdir(args.input):
        import pnpba

        pairs = tum_pairs(args.input, parse_pairs_rule(args.pairs))
        # evaluate_tum's rule (tum_cameras.h): --camera, the folder's camera.yaml, the freiburg
        # camera its path names, else freiburg1; said, since a wrong one costs accuracy quietly.
        try:
            chosen = pnpba.tum_camera_for_folder(args.input, args.camera or "")
        except pnpba.Error as e:
            raise InputError(str(e))
        print(f"pnpba-batch: camera: {chosen['source']}", file=sys.stderr)
        camera = ("tum", chosen["freiburg"]) if chosen["freiburg"] else chosen["source"]
        return pairs, camera
    if not os.path.exists(args.input):
        raise InputError(f"{args.input}: no such file or folder")
    return read_pair_table(args.input), args.camera


def two_view_options(args):
    keys = [key for key, _ in TWO_VIEW_OPTIONS.values()] + ["undistort", "retry_with_sift",
                                                           "fuse_agreeing"]
    return {k: getattr(args, k) for k in keys if getattr(args, k) is not None}


def _client(args):
    from distributed import Client, LocalCluster

    if args.scheduler:
        return Client(args.scheduler, timeout="30s"), None
    # One process, `workers` threads: the estimator releases the GIL. The scheduler always
    # serves HTTP (health routes); a free port keeps it from colliding with another cluster.
    cluster = LocalCluster(n_workers=1, threads_per_worker=args.workers, processes=False,
                           dashboard_address="127.0.0.1:0")
    return Client(cluster), cluster


def _check_options(options, camera):
    """Fails fast, before any task, on options or a camera the estimator would refuse."""
    import pnpba

    try:
        pnpba.check_two_view_options(**options)
        camera_from_spec(camera)
    except TypeError as e:
        raise InputError(f"options: {e}")
    except (pnpba.Error, ValueError) as e:
        raise InputError(str(e))


def run(args):
    pairs, camera = load_pairs(args)
    if args.check_chain and not any(p.get("stamp1") is not None for p in pairs):
        raise InputError(f"{args.input}: --check-chain needs a TUM folder (its frames' order)")
    options = two_view_options(args)
    _check_options(options, camera)
    done = read_results(args.output)
    done_ids = {r.get("id") for r in done}
    pending = [p for p in pairs if p["id"] not in done_ids]
    counts = {"ok": sum(1 for r in done if r.get("ok")), "refused": 0, "error": 0}
    for r in done:
        if not r.get("ok"):
            counts["error" if "error" in r else "refused"] += 1
    print(f"pnpba-batch: {len(pairs)} pairs, {len(pairs) - len(pending)} already in "
          f"{args.output}, {len(pending)} to run", file=sys.stderr)
    records = list(done)
    if pending:
        records += _run_pending(args, pending, options, camera, counts)
    from pnpba.graph_files import write_chain_check, write_csv, write_g2o, write_trajectory

    contradicted = []
    if args.check_chain:
        tested, contradicted = write_chain_check(args.check_chain, pairs, records)
        shown = ", ".join(contradicted[:10]) + (", ..." if len(contradicted) > 10 else "")
        print(f"pnpba-batch: {args.check_chain}: {tested} poses tested against the chained "
              f"consecutive pairs, {len(contradicted)} contradicted" +
              (f" ({shown}{'; left out of --g2o' if args.g2o else ''})" if contradicted else ""),
              file=sys.stderr)
    if args.g2o:
        edges = write_g2o(args.g2o, pairs, records, leave_out=set(contradicted))
        print(f"pnpba-batch: {args.g2o}: {edges} edges", file=sys.stderr)
    if args.trajectory:
        poses = write_trajectory(args.trajectory, pairs, records)
        print(f"pnpba-batch: {args.trajectory}: {poses} poses", file=sys.stderr)
    if args.csv:
        write_csv(args.csv, records)
    return 0


def _read_images(pair):
    images = {}
    for f in PATH_FIELDS:
        if pair.get(f) and os.path.isfile(pair[f]):
            with open(pair[f], "rb") as fh:
                images[f] = fh.read()
    return images


def _run_pending(args, pending, options, camera, counts):
    """Submits the pairs as Dask tasks, a bounded window ahead of the results (a million pairs
    are not a million futures, nor a million images in memory when shipped), and appends each
    record as it arrives. Dask reschedules the tasks of a worker that dies."""
    from distributed import as_completed

    writer = ResultsWriter(args.output)
    client, cluster = _client(args)
    records = []
    progress = None
    if not args.quiet:
        from tqdm import tqdm

        progress = tqdm(total=len(pending), unit="pair", file=sys.stderr, dynamic_ncols=True)
    threads = sum(client.nthreads().values()) or 1
    window = max(32, 8 * threads)
    todo = iter(pending)
    futures = set()

    def submit():
        pair = next(todo, None)
        if pair is None:
            return None
        # One future per pair's bytes (a scattered dict would use its keys, 'rgb1', ..., as the
        # data's names, shared by every pair).
        images = client.scatter([_read_images(pair)], hash=False)[0] if args.ship_images else None
        future = client.submit(estimate_pair, pair, options, camera, images,
                               key=f"pnpba-{pair['id']}-{time.time_ns()}", pure=False)
        futures.add(future)
        return future

    try:
        running = as_completed([f for f in (submit() for _ in range(window)) if f is not None])
        for future in running:
            record = future.result()
            futures.discard(future)
            writer.append(record)
            records.append(record)
            counts["ok" if record.get("ok") else "error" if "error" in record else "refused"] += 1
            if progress:
                progress.set_postfix(counts, refresh=False)
                progress.update(1)
            following = submit()
            if following is not None:
                running.add(following)
    except KeyboardInterrupt:
        for f in futures:
            f.cancel()
        raise
    finally:
        if progress:
            progress.close()
        writer.close()
        client.close()
        if cluster is not None:
            cluster.close()
    return records


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if sys.flags.no_site:
        # pnpba-batch starts its interpreter without the site module (-S), 2 ms of --help; the
        # work needs its folders (NumPy, OpenCV, Dask) on the path.
        import site

        site.main()
    try:
        return run(args)
    except InputError as e:
        print(f"pnpba-batch: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"pnpba-batch: interrupted; {args.output} holds every finished pair, rerun the same "
              "command to resume", file=sys.stderr)
        return 130
    except OSError as e:
        print(f"pnpba-batch: {e.filename or args.output}: {e.strerror or e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    # Run the imported module's main, not this __main__ copy: the tasks must name
    # pnpba.batch.estimate_pair, which every worker imports, not __main__'s.
    from pnpba.batch import main as batch_main

    sys.exit(batch_main())
