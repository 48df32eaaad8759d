"""pnpba.batch: the same poses as the CLI, on a local cluster and on a real Dask scheduler with
workers over TCP; resume, bad pairs, a worker killed mid-job; the g2o graph read back."""
import json
import math
import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

pytest.importorskip("distributed")

from pnpba import batch, graph_files  # noqa: E402
from se3 import se3_exp  # noqa: E402

HEADER = "id\trgb1\tdepth1\trgb2\tdepth2\n"


def images(paths):
    return os.path.join(paths["source"], "data", "images")


def write_table(tmp_path, paths, rows):
    folder = images(paths)
    lines = [HEADER]
    for row in rows:
        lines.append("\t".join([row[0]] + [os.path.join(folder, f) if f != "-" else "-"
                                           for f in row[1:]]) + "\n")
    table = tmp_path / "pairs.tsv"
    table.write_text("".join(lines))
    return table


# Three different pairs of the rendered sample: forward, backward, and without depth 2.
ROWS = [("fwd", "1.png", "1_depth.png", "2.png", "2_depth.png"),
        ("back", "2.png", "2_depth.png", "1.png", "1_depth.png"),
        ("nodepth2", "1.png", "1_depth.png", "2.png", "-")]


def run_batch(*argv):
    return batch.main([str(a) for a in argv])


def records(path):
    return [json.loads(line) for line in open(path)]


def cli_pose(paths, pair, camera):
    files = [pair["rgb1"], pair["rgb2"], pair["depth1"]] + ([pair["depth2"]] if pair["depth2"] else [])
    out = subprocess.run([paths["pose_cli"], *files, "--camera", camera, "--json", "/dev/stdout"],
                         capture_output=True, text=True)
    return json.loads(out.stdout)


def test_local_run_equals_the_cli_pair_by_pair(paths, tmp_path):
    table = write_table(tmp_path, paths, ROWS)
    camera = os.path.join(images(paths), "camera.yaml")
    out = tmp_path / "r.jsonl"
    assert run_batch(table, "--output", out, "--camera", camera, "--workers", 2, "--quiet") == 0
    got = {r["id"]: r for r in records(out)}
    assert sorted(got) == sorted(r[0] for r in ROWS)
    for r in got.values():
        cli = cli_pose(paths, r, camera)
        assert r["ok"] == cli["ok"] and r["path"] == cli["path"]
        np.testing.assert_allclose(np.array(r["T"]), np.array(cli["T"]), rtol=0, atol=1e-9)
        np.testing.assert_allclose(np.array(r["covariance"]), np.array(cli["covariance"]),
                                   rtol=1e-9, atol=0)
        assert set(r["timings_ms"]) == set(cli["timings_ms"])
    # The backward pair is the forward pair's inverse (a check of the pairing, not of the CLI).
    T_fwd, T_back = np.array(got["fwd"]["T"]), np.array(got["back"]["T"])
    assert np.linalg.norm(T_fwd @ T_back - np.eye(4)) < 0.02


def test_resume_skips_done_pairs_and_a_bad_pair_is_recorded(paths, tmp_path):
    broken = tmp_path / "broken.png"
    broken.write_bytes(b"\x89PNG\r\n\x1a\n not really")
    rows = ROWS + [("broken", str(broken), "1_depth.png", "2.png", "2_depth.png"),
                   ("missing", "nope.png", "1_depth.png", "2.png", "2_depth.png")]
    table = write_table(tmp_path, paths, rows)
    camera = os.path.join(images(paths), "camera.yaml")
    out = tmp_path / "r.jsonl"
    assert run_batch(table, "--output", out, "--camera", camera, "--quiet") == 0
    first = {r["id"]: r for r in records(out)}
    assert len(first) == len(rows)
    assert not first["broken"]["ok"] and str(broken) in first["broken"]["error"]
    assert not first["missing"]["ok"] and "no such file" in first["missing"]["error"]
    # An interrupted run: the last record lost and half a line left behind.
    lines = open(out).read().splitlines()
    lost = json.loads(lines[-1])["id"]
    with open(out, "w") as f:
        f.write("\n".join(lines[:-1]) + "\n" + lines[-1][:40])
    assert run_batch(table, "--output", out, "--camera", camera, "--quiet") == 0
    again = records(out)
    assert sorted(r["id"] for r in again) == sorted(first)  # each pair exactly once
    assert again[-1]["id"] == lost
    for r in again[:-1]:
        assert r == first[r["id"]]  # untouched


def test_bad_input_is_one_line_and_exit_2(paths, tmp_path, capsys):
    bad = tmp_path / "bad.tsv"
    bad.write_text("id\trgb1\n1\ta.png\n")
    assert run_batch(bad, "--output", tmp_path / "r.jsonl") == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(bad) in err[0] and "header lacks" in err[0]
    table = write_table(tmp_path, paths, ROWS[:1])
    assert run_batch(table, "--output", tmp_path / "r.jsonl", "--features", "-5") == 2
    assert "features" in capsys.readouterr().err
    assert run_batch(tmp_path / "absent", "--output", tmp_path / "r.jsonl") == 2
    assert not (tmp_path / "r.jsonl").exists()  # nothing written for bad input


def test_the_help_width_is_shutils(monkeypatch):
    # batch.help_width stands in for shutil.get_terminal_size in argparse's help (its import
    # is left out of --help's start): the same width with COLUMNS set, unset, or not a number.
    import shutil

    for columns in ("60", "200", None, "wide", "0"):
        if columns is None:
            monkeypatch.delenv("COLUMNS", raising=False)
        else:
            monkeypatch.setenv("COLUMNS", columns)
        assert batch.help_width() == shutil.get_terminal_size().columns - 2, columns


def test_the_command_runs_its_module_after_adding_the_site_folders(paths, tmp_path):
    # build/python/pnpba-batch starts its interpreter without site (-S): its help as the
    # module's, and a run that gets past the arguments has NumPy, OpenCV and Dask to hand (an
    # unreadable image is then a recorded pair, not an ImportError).
    command = os.path.join(os.path.dirname(os.path.dirname(batch.__file__)), "pnpba-batch")
    env = dict(os.environ, COLUMNS="70")
    help_text = subprocess.run([command, "--help"], env=env, capture_output=True, text=True,
                               check=True).stdout
    assert help_text == subprocess.run([sys.executable, "-m", "pnpba.batch", "--help"], env=env,
                                       capture_output=True, text=True, check=True).stdout
    assert max(len(line) for line in help_text.splitlines()) <= 70
    table = write_table(tmp_path, paths, ROWS[:1])
    table.write_text(table.read_text().replace("1_depth.png", "absent.png"))
    out = tmp_path / "r.jsonl"
    run = subprocess.run([command, table, "--output", out, "--quiet", "--workers", "1",
                          "--camera", os.path.join(images(paths), "camera.yaml")],
                         env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    (record,) = records(out)
    assert record["ok"] is False and "absent.png" in record["error"]


def test_the_help_kept_by_the_build_is_argparses(tmp_path):
    # At 80 columns (a pipe, or COLUMNS=80) pnpba-batch prints the help the build kept, without
    # starting argparse; it must be argparse's text byte for byte, for -h and --help. Any other
    # width, or --help among other arguments, is argparse's to answer.
    from pnpba import batch_help

    command = os.path.join(os.path.dirname(os.path.dirname(batch.__file__)), "pnpba-batch")
    env = {k: v for k, v in os.environ.items() if k != "COLUMNS"}
    argparse_text = subprocess.run([sys.executable, "-m", "pnpba.batch", "--help"], env=env,
                                   capture_output=True, text=True, check=True).stdout
    assert argparse_text == batch.help_text(batch_help.PREBUILT_WIDTH)
    # PYTHONVERBOSE: an interpreter that starts reports every import on stderr.
    verbose = dict(env, PYTHONVERBOSE="1")
    for flag in ("-h", "--help"):
        run = subprocess.run([command, flag], env=verbose, capture_output=True, text=True,
                             check=True)
        assert run.stdout == argparse_text, flag
        assert run.stderr == ""  # the kept text, printed without starting Python
    assert batch_help.prebuilt_help(["--help", "x.tsv"]) is None
    # As argparse: without a stdout the help goes to stderr, and the exit is 0.
    for columns, expected in ((None, argparse_text), ("100", batch.help_text(98))):
        closed = subprocess.run([command, "--help"],
                                env=dict(env, COLUMNS=columns) if columns else env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                preexec_fn=lambda: os.close(1))
        assert closed.returncode == 0 and closed.stderr == expected, columns
    wide = dict(verbose, COLUMNS="120")
    run = subprocess.run([command, "--help"], env=wide, capture_output=True, text=True,
                         check=True)
    assert "import 'argparse'" in run.stderr
    assert run.stdout == batch.help_text(118) != argparse_text
    # Written by the build whole or not at all.
    batch_help.write_prebuilt_help(tmp_path)
    assert (tmp_path / "batch_help_78.txt").read_text() == argparse_text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["batch_help_78.txt"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def dask_cluster():
    """A real `dask scheduler` and two `dask worker` processes on 127.0.0.1, shut down after."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ)
    procs = [subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
                               "127.0.0.1", "--port", str(port), "--no-dashboard"],
                              env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    workers = []
    try:
        for _ in range(2):
            workers.append(subprocess.Popen(
                [sys.executable, "-m", "distributed.cli.dask_worker", address, "--nthreads", "1",
                 "--no-dashboard", "--no-nanny"],
                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client

        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
        yield address, workers
    finally:
        for p in workers + procs:
            if p.poll() is None:
                p.terminate()
        for p in workers + procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


def test_a_dask_scheduler_over_tcp_gives_the_local_results(paths, tmp_path, dask_cluster):
    address, _ = dask_cluster
    table = write_table(tmp_path, paths, ROWS)
    camera = os.path.join(images(paths), "camera.yaml")
    local, remote, shipped = tmp_path / "local.jsonl", tmp_path / "remote.jsonl", tmp_path / "s.jsonl"
    assert run_batch(table, "--output", local, "--camera", camera, "--quiet") == 0
    assert run_batch(table, "--output", remote, "--camera", camera, "--scheduler", address,
                     "--quiet") == 0
    assert run_batch(table, "--output", shipped, "--camera", camera, "--scheduler", address,
                     "--ship-images", "--quiet") == 0
    a = {r["id"]: r for r in records(local)}
    for other in (records(remote), records(shipped)):
        assert sorted(r["id"] for r in other) == sorted(a)
        for r in other:
            np.testing.assert_allclose(np.array(r["T"]), np.array(a[r["id"]]["T"]), rtol=0,
                                       atol=1e-9)


def test_a_worker_killed_mid_job_loses_no_pair(paths, tmp_path, dask_cluster):
    address, workers = dask_cluster
    rows = [(f"p{i:03d}",) + ROWS[i % 3][1:] for i in range(90)]
    table = write_table(tmp_path, paths, rows)
    camera = os.path.join(images(paths), "camera.yaml")
    out = tmp_path / "r.jsonl"
    job = subprocess.Popen([sys.executable, "-m", "pnpba.batch", str(table), "--output", str(out),
                            "--camera", camera, "--scheduler", address, "--quiet",
                            "--features", "3000"],
                           env=dict(os.environ), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.time() + 120
    while time.time() < deadline and (not out.exists() or len(open(out).readlines()) < 5):
        time.sleep(0.05)
    done_before_kill = len(open(out).readlines())
    workers[0].send_signal(signal.SIGKILL)
    _, err = job.communicate(timeout=300)
    assert job.returncode == 0, err.decode()
    ids = [r["id"] for r in records(out)]
    assert done_before_kill < len(rows)  # the kill came mid-job
    assert sorted(ids) == sorted(r[0] for r in rows)  # every pair exactly once


def test_g2o_edges_read_back_match_the_json_lines(paths, tmp_path):
    table = write_table(tmp_path, paths, ROWS[:2])
    camera = os.path.join(images(paths), "camera.yaml")
    out, g2o = tmp_path / "r.jsonl", tmp_path / "graph.g2o"
    assert run_batch(table, "--output", out, "--camera", camera, "--g2o", g2o, "--quiet") == 0
    by_id = {r["id"]: r for r in records(out)}
    vertices, edges = {}, []
    for line in open(g2o):
        t = line.split()
        if t[0] == "VERTEX_SE3:QUAT":
            vertices[int(t[1])] = [float(v) for v in t[2:]]
        elif t[0] == "EDGE_SE3:QUAT":
            edges.append((int(t[1]), int(t[2]), [float(v) for v in t[3:10]],
                          [float(v) for v in t[10:]]))
    assert len(vertices) == 2 and len(edges) == 2
    for (i, j, meas, upper), pair_id in zip(edges, ["fwd", "back"]):
        r = by_id[pair_id]
        # The measurement is frame 2 in frame 1: T_12 = T_21^-1 (g2o: from^-1 * to).
        T12 = np.linalg.inv(np.array(r["T"]))
        np.testing.assert_allclose(meas[:3], T12[:3, 3], atol=1e-8)
        R = quaternion_matrix(meas[3:])
        np.testing.assert_allclose(R, T12[:3, :3], atol=1e-8)
        info = np.zeros((6, 6))
        info[np.triu_indices(6)] = upper
        info = info + info.T - np.diag(np.diag(info))
        # Independently of the conversion's derivation: a small error d of our covariance's
        # tangent (left perturbation of T_21) has the same Mahalanobis length as g2o's error of
        # the resulting measurement, computed the way g2o does (Z^-1 * T, [t; qvec]).
        C = np.array(r["covariance"])
        rng = np.random.default_rng(1)
        for _ in range(5):
            d = rng.multivariate_normal(np.zeros(6), C) * 1e-2
            T21 = se3_exp(d) @ np.array(r["T"])
            delta = np.linalg.inv(T12) @ np.linalg.inv(T21)
            e = np.concatenate([delta[:3, 3], graph_files._quaternion(delta[:3, :3])[:3]])
            ours = d @ np.linalg.solve(C, d)
            theirs = e @ info @ e
            assert math.isclose(ours, theirs, rel_tol=2e-3), (ours, theirs)


def quaternion_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_tum_folder_within_k_and_the_trajectory(paths, tmp_path):
    if paths["shared"] is None:
        pytest.skip("shared data not found (PNPBA_SHARED_DATA)")
    folder = os.path.join(paths["shared"], "tum_fr1_desk")
    out, traj = tmp_path / "r.jsonl", tmp_path / "traj.txt"
    assert run_batch(folder, "--output", out, "--pairs", "within:2", "--quiet") == 0
    got = records(out)
    n = len(__import__("pnpba").tum_frames(folder))
    assert len(got) == (n - 1) + (n - 2)  # (i, i+1) and (i, i+2)
    assert sum(r["ok"] for r in got) == len(got)
    # The trajectory from the same results file: every frame, chained.
    assert run_batch(folder, "--output", out, "--pairs", "within:2", "--trajectory", traj,
                     "--quiet") == 0
    lines = open(traj).read().splitlines()
    assert len(lines) == n
    assert all(len(line.split()) == 8 for line in lines)


def test_check_chain_tests_far_poses_against_the_consecutive_ones(paths, tmp_path, capsys):
    if paths["shared"] is None:
        pytest.skip("shared data not found (PNPBA_SHARED_DATA)")
    folder = os.path.join(paths["shared"], "tum_fr1_desk")
    out, report, graph = tmp_path / "r.jsonl", tmp_path / "chain.tsv", tmp_path / "g.g2o"
    assert run_batch(folder, "--output", out, "--pairs", "within:3", "--check-chain", report,
                     "--g2o", graph, "--quiet") == 0
    got = records(out)
    n = len(__import__("pnpba").tum_frames(folder))
    rows = [line.split("\t") for line in open(report).read().splitlines()]
    assert rows[0] == ["id", "frame1", "frame2", "chi2", "contradicted"]
    # Every pair two or three frames apart has its consecutive pairs (all accepted here), and
    # fr1_desk's poses agree with their chains: none is left out of the graph.
    assert len(rows) - 1 == (n - 2) + (n - 3)
    assert all(int(r[2]) - int(r[1]) >= 2 and float(r[3]) < 22.46 and r[4] == "0"
               for r in rows[1:])
    edges = [line for line in open(graph) if line.startswith("EDGE_SE3:QUAT")]
    assert len(edges) == sum(r["ok"] for r in got)
    assert "0 contradicted" in capsys.readouterr().err
    # A report that cannot be written: one line naming the path given, exit 2.
    absent = tmp_path / "absent" / "chain.tsv"
    assert run_batch(folder, "--output", out, "--pairs", "within:3", "--check-chain", absent,
                     "--quiet") == 2
    assert capsys.readouterr().err.strip().splitlines()[-1] == (
        f"pnpba-batch: {absent}: No such file or directory")
    assert not (tmp_path / "absent").exists()
    # A pair table has no frame order to chain: one line, exit 2, before any pair runs.
    table = write_table(tmp_path, paths, ROWS[:1])
    assert run_batch(table, "--output", tmp_path / "t.jsonl", "--check-chain", report) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(table) in err[0] and "--check-chain" in err[0]
    assert not (tmp_path / "t.jsonl").exists()


def test_a_tum_folder_gets_the_camera_its_name_says_and_says_which(paths, tmp_path, capsys):
    if paths["shared"] is None:
        pytest.skip("shared data not found (PNPBA_SHARED_DATA)")
    import pnpba

    desk = os.path.join(paths["shared"], "tum_fr1_desk")
    named = tmp_path / "rgbd_dataset_freiburg3_desk"  # the same frames under a fr3 name
    os.symlink(desk, named)
    pairs, camera = batch.load_pairs(batch.parse_args([str(named), "--output", "r"]))
    assert camera == ("tum", 3) and len(pairs) == 8
    assert "camera: TUM freiburg3 (named by the folder)" in capsys.readouterr().err
    fr3 = batch.camera_from_spec(camera)
    assert (fr3.fx, fr3.fy, fr3.cx, fr3.cy) == (535.4, 539.2, 320.1, 247.6)
    # --camera outranks the name; a name that says nothing gets freiburg1, said as assumed.
    yaml = os.path.join(images(paths), "camera.yaml")
    _, camera = batch.load_pairs(batch.parse_args([str(named), "--output", "r", "--camera", yaml]))
    assert camera == yaml
    plain = tmp_path / "sequence"
    os.symlink(desk, plain)
    _, camera = batch.load_pairs(batch.parse_args([str(plain), "--output", "r"]))
    assert camera == ("tum", 1)
    assert "TUM freiburg1 (assumed" in capsys.readouterr().err
    chosen = pnpba.tum_camera_for_folder(str(plain))
    assert chosen["assumed"] and chosen["freiburg"] == 1
    assert chosen["camera"].fx == pnpba.tum_camera(1).fx == 517.3
    with pytest.raises(pnpba.Error):
        pnpba.tum_camera(4)


def test_ctrl_c_leaves_a_valid_file_and_the_rerun_completes_it(paths, tmp_path):
    rows = [(f"p{i:03d}",) + ROWS[i % 3][1:] for i in range(60)]
    table = write_table(tmp_path, paths, rows)
    camera = os.path.join(images(paths), "camera.yaml")
    out = tmp_path / "r.jsonl"
    argv = [sys.executable, "-m", "pnpba.batch", str(table), "--output", str(out), "--camera",
            camera, "--quiet", "--features", "3000", "--workers", "1"]
    job = subprocess.Popen(argv, env=dict(os.environ), stderr=subprocess.PIPE)
    deadline = time.time() + 120
    while time.time() < deadline and (not out.exists() or len(open(out).readlines()) < 3):
        time.sleep(0.02)
    job.send_signal(signal.SIGINT)
    _, err = job.communicate(timeout=120)
    assert job.returncode == 130, err.decode()
    assert "rerun the same command to resume" in err.decode()
    partial = records(out)  # every line whole and valid JSON
    assert 3 <= len(partial) < len(rows)
    subprocess.run(argv, env=dict(os.environ), check=True, capture_output=True)
    assert sorted(r["id"] for r in records(out)) == sorted(r[0] for r in rows)


def test_per_row_intrinsics_and_camera_files(paths, tmp_path):
    # The sample camera given three ways: --camera, a row's camera file, a row's intrinsics.
    import pnpba

    folder = images(paths)
    yaml = os.path.join(folder, "camera.yaml")
    cam = pnpba.Camera.from_yaml(yaml)
    files = [os.path.join(folder, f) for f in ROWS[0][1:]]
    table = tmp_path / "pairs.tsv"
    table.write_text(
        "id\trgb1\tdepth1\trgb2\tdepth2\tcamera\tfx\tfy\tcx\tcy\tdepth_scale\n"
        + "\t".join(["plain", *files, "", "", "", "", "", ""]) + "\n"
        + "\t".join(["file", *files, yaml, "", "", "", "", ""]) + "\n"
        + "\t".join(["inline", *files, "", repr(cam.fx), repr(cam.fy), repr(cam.cx), repr(cam.cy),
                     repr(cam.depth_scale)]) + "\n")
    out = tmp_path / "r.jsonl"
    assert run_batch(table, "--output", out, "--camera", yaml, "--quiet") == 0
    got = {r["id"]: np.array(r["T"]) for r in records(out)}
    assert np.abs(got["file"] - got["plain"]).max() < 1e-12
    assert np.abs(got["inline"] - got["plain"]).max() < 1e-12
    bad = tmp_path / "bad.tsv"
    bad.write_text("id\trgb1\tdepth1\trgb2\tdepth2\tfx\tfy\tcx\tcy\n"
                   + "\t".join(["x", *files, "abc", "1", "1", "1"]) + "\n")
    assert run_batch(bad, "--output", tmp_path / "b.jsonl") == 2


def test_the_decoded_image_cache_sees_a_changed_file(paths, tmp_path):
    import shutil

    copy = tmp_path / "1.png"
    shutil.copy(os.path.join(images(paths), "1.png"), copy)
    first = batch._decode("rgb1", str(copy), None, False)
    assert batch._decode("rgb1", str(copy), None, False) is first  # cached
    assert not first.flags.writeable  # shared between pairs: read-only
    copy.write_bytes(b"not an image any more")
    with pytest.raises(batch.InputError, match="not a readable image"):
        batch._decode("rgb1", str(copy), None, False)


def test_a_worker_opens_no_open3d_for_a_pair_on_the_depth_path(paths):
    """The depth registration is pnpba's own: a worker that runs it (depth_path always) opens
    neither Open3D nor its plugin, in a process of its own so that no other test has."""
    folder = images(paths)
    pair = {"id": "fwd", **{f: os.path.join(folder, name) for f, name in
                            zip(batch.PATH_FIELDS, ROWS[0][1:])}}
    code = (
        "import json, sys\n"
        "from pnpba import batch\n"
        "pair, camera = json.loads(sys.argv[1]), sys.argv[2]\n"
        "record = batch.estimate_pair(pair, {'depth_path': 'always'}, camera)\n"
        "maps = open('/proc/self/maps').read()\n"
        "print(json.dumps({'ok': record['ok'], 'path': record.get('path'),\n"
        "                  'open3d': 'libOpen3D' in maps or 'libpnpba_open3d' in maps}))\n")
    done = subprocess.run([sys.executable, "-c", code, json.dumps(pair),
                           os.path.join(folder, "camera.yaml")],
                          capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    assert seen["ok"] and seen["path"] in ("depth-registration", "both"), seen
    assert not seen["open3d"], seen


def test_a_frame_in_several_pairs_is_described_once(paths):
    """A worker describes each colour image once (pnpba.describe_frame) and the records are the
    CLI's, which describes both images of every pair."""
    folder = images(paths)
    camera = os.path.join(folder, "camera.yaml")
    pairs = [{"id": row[0], **{f: os.path.join(folder, name) if name != "-" else None
                                for f, name in zip(batch.PATH_FIELDS, row[1:])}} for row in ROWS]
    batch._features_cached.cache_clear()
    got = [batch.estimate_pair(pair, {}, camera) for pair in pairs]
    info = batch._features_cached.cache_info()
    assert (info.misses, info.hits) == (2, 4)  # 1.png and 2.png, in three pairs
    for record, pair in zip(got, pairs):
        cli = cli_pose(paths, pair, camera)
        assert record["ok"] == cli["ok"] and record["path"] == cli["path"]
        np.testing.assert_array_equal(np.array(record["T"]), np.array(cli["T"]))
        np.testing.assert_array_equal(np.array(record["covariance"]),
                                      np.array(cli["covariance"]))
    # Other feature options are other features.
    batch.estimate_pair(pairs[0], {"features": 1000}, camera)
    assert batch._features_cached.cache_info().misses == 4


def test_a_workers_frames_keep_the_sift_retrys_features(paths, tmp_path):
    """A rendered tiled room turned 45 degrees, whose pair needs the SIFT retry, estimated twice:
    after the first, the worker's described frames hold the retry's features, the second takes
    them, and both records are the CLI's."""
    render = os.path.join(os.path.dirname(paths["pose_cli"]), "render_synthetic")
    subprocess.run([render, "--output", str(tmp_path), "--scene", "room", "--texture", "tiled",
                    "--rotation-deg", "45", "--translation-m", "0.25"], check=True,
                   capture_output=True)
    names = ("1.png", "1_depth.png", "2.png", "2_depth.png")
    pair = {"id": "tiled", **{f: str(tmp_path / n) for f, n in zip(batch.PATH_FIELDS, names)}}
    camera = str(tmp_path / "camera.yaml")
    batch._features_cached.cache_clear()
    first = batch.estimate_pair(pair, {}, camera)
    assert first["timings_ms"]["sift_retry"] > 0, "the retry did not run: nothing is exercised"
    frames = [batch._frame_features(pair[f], None, {}) for f in ("rgb1", "rgb2")]
    assert [f.later_features for f in frames] == [1, 1]
    second = batch.estimate_pair(pair, {}, camera)
    cli = cli_pose(paths, pair, camera)
    for record in (first, second):
        assert record["ok"] == cli["ok"] and record["detector"] == cli["detector"]
        np.testing.assert_array_equal(np.array(record["T"]), np.array(cli["T"]))
        np.testing.assert_array_equal(np.array(record["covariance"]),
                                      np.array(cli["covariance"]))


def test_a_workers_key_frame_keeps_its_depth_description(paths, cabinet_from_one_key_frame):
    """The rendered cabinet from one key frame after two motions, each pair registering the
    depths: after the first, the worker's described key frame holds its depth's description, the
    second pair takes it, and both records are the CLI's."""
    names = ("1.png", "1_depth.png", "2.png", "2_depth.png")
    pairs = []
    for folder in cabinet_from_one_key_frame:
        pair = {"id": folder.name, **{f: str(folder / n) for f, n in zip(batch.PATH_FIELDS, names)}}
        if pairs:  # one key frame: the second pair's frame 1 is the first pair's files
            pair["rgb1"], pair["depth1"] = pairs[0]["rgb1"], pairs[0]["depth1"]
        pairs.append(pair)
    camera = str(cabinet_from_one_key_frame[0] / "camera.yaml")
    batch._features_cached.cache_clear()
    key = batch._frame_features(pairs[0]["rgb1"], None, {})
    records = []
    for pair in pairs:
        records.append(batch.estimate_pair(pair, {}, camera))
        assert records[-1]["timings_ms"]["registration"] > 0, "no registration: nothing exercised"
        assert key.later_depth_descriptions == 1
    for pair, record in zip(pairs, records):
        cli = cli_pose(paths, pair, camera)
        assert record["ok"] == cli["ok"] and record.get("failure") == cli.get("failure")
        if cli["ok"]:
            np.testing.assert_array_equal(np.array(record["T"]), np.array(cli["T"]))
            np.testing.assert_array_equal(np.array(record["covariance"]),
                                          np.array(cli["covariance"]))
