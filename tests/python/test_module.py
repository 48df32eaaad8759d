"""The module reads well: documented, typed, and evaluate_tum reachable."""
import os
import subprocess
import sys

import pytest

import pnpba


def test_every_public_name_is_documented():
    assert pnpba.__doc__
    for name in pnpba.__all__:
        assert getattr(pnpba, name).__doc__, name


def test_type_stubs_are_shipped():
    folder = os.path.dirname(pnpba.__file__)
    for stub in ("__init__.pyi", "_pnpba.pyi", "py.typed"):
        assert os.path.isfile(os.path.join(folder, stub)), stub
    # The package's stub names what the package gives.
    with open(os.path.join(folder, "__init__.pyi")) as f:
        stub = f.read()
    assert all(f"import {name} as {name}" in stub for name in pnpba.__all__)


def test_the_extension_and_numpy_load_only_when_used():
    # A fresh interpreter: what `import pnpba` and pnpba-batch's module load by themselves.
    probe = ("import sys, pnpba, pnpba.batch; "
             "print(int('pnpba._pnpba' in sys.modules), int('numpy' in sys.modules)); "
             "pnpba.Camera; print(int('pnpba._pnpba' in sys.modules))")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         check=True, env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    assert out.stdout.split() == ["0", "0", "1"]
    assert set(pnpba.__all__) <= set(dir(pnpba))
    with pytest.raises(AttributeError, match="no attribute 'Camra'"):
        pnpba.Camra


def test_evaluate_tum_on_the_shared_sequence(paths):
    if paths["shared"] is None:
        pytest.skip("shared data not found (PNPBA_SHARED_DATA)")
    lines = []
    report = pnpba.evaluate_tum(os.path.join(paths["shared"], "tum_fr1_desk"), methods=["rgbd"],
                                max_gap=1, progress=lines.append)
    row = report["methods"][0]
    assert row["method"] == "rgbd" and row["pairs"] == len(report["pairs"]) == len(lines)
    # The depth path's registration is pnpba's own: no method opened Open3D's plugin.
    assert report["plugin_load_ms"] == -1
    # Ground truth: consecutive fr1_desk frames are estimated within 1 deg / 2 cm.
    assert row["median_rot_deg"] < 1.0 and row["median_trans_cm"] < 2.0
    # The sensor sigmas reach the covariance: without the calibration and motion terms every
    # pair's 1-sigma shrinks and its pose error stays.
    bare = pnpba.evaluate_tum(os.path.join(paths["shared"], "tum_fr1_desk"), methods=["rgbd"],
                              max_gap=1, focal_sigma=0, principal_point_sigma=0,
                              depth_scale_sigma=0, motion_sigma=0)
    for with_model, without in zip(report["pairs"], bare["pairs"]):
        assert without["rgbd"]["rot_deg"] == with_model["rgbd"]["rot_deg"]
        assert without["rgbd"]["sigma_deg"] < with_model["rgbd"]["sigma_deg"]
        assert without["rgbd"]["sigma_cm"] < with_model["rgbd"]["sigma_cm"]
    # fuse_agreeing is taken; no consecutive fr1_desk pair runs the depth path, so nothing moves.
    kept = pnpba.evaluate_tum(os.path.join(paths["shared"], "tum_fr1_desk"), methods=["rgbd"],
                              max_gap=1, fuse_agreeing=False)
    def untimed(pairs):
        return [{k: v for k, v in p["rgbd"].items() if k != "time_ms"} for p in pairs]

    assert untimed(kept["pairs"]) == untimed(report["pairs"])


def test_evaluate_tum_runs_the_baselines_side_by_side(paths):
    if paths["shared"] is None:
        pytest.skip("shared data not found (PNPBA_SHARED_DATA)")
    report = pnpba.evaluate_tum(os.path.join(paths["shared"], "tum_fr1_desk"),
                                methods=["rgbd", "opencv", "open3d"], max_gap=1)
    rows = {row["method"]: row for row in report["methods"]}
    assert set(rows) == {"rgbd", "opencv", "open3d"}
    # Consecutive fr1_desk frames (about 1 deg apart): Open3D's odometry, opened from its plugin,
    # gets them within 2 deg / 5 cm of the ground truth as pnpba does.
    for name in ("opencv", "open3d"):
        assert rows[name]["failures"] == 0, name
        assert rows[name]["within_2deg_5cm"] == rows[name]["pairs"] == 8, name
    for pair in report["pairs"]:
        assert pair["open3d"]["ok"] and "sigma_deg" not in pair["open3d"]


def test_examples_run(paths, tmp_path):
    import subprocess
    import sys

    import cv2
    import numpy as np

    img = os.path.join(paths["source"], "data", "images")
    png = tmp_path / "matches.png"
    out = subprocess.run([sys.executable, os.path.join(paths["source"], "examples", "two_view.py"),
                          f"{img}/1.png", f"{img}/2.png", f"{img}/1_depth.png",
                          f"{img}/2_depth.png", "--camera", f"{img}/camera.yaml",
                          "--matches", str(png)], capture_output=True, text=True, check=True)
    assert "1-sigma" in out.stdout
    drawing = cv2.imread(str(png))
    assert drawing.shape[1] == 2 * cv2.imread(f"{img}/1.png").shape[1]
    if paths["shared"] is not None:
        out = subprocess.run([sys.executable, os.path.join(paths["source"], "examples", "bal.py"),
                              os.path.join(paths["shared"], "bal", "dubrovnik-3-7-pre.txt"),
                              "--iterations", "5"], capture_output=True, text=True, check=True)
        assert "->" in out.stdout

    if paths["shared"] is not None:
        # Odometry, each frame described once: the trajectory pnpba-batch chains from the same
        # consecutive pairs (each estimated with both images described), to the printed digit.
        folder = os.path.join(paths["shared"], "tum_fr1_desk")
        ours, batch_traj = tmp_path / "odometry.txt", tmp_path / "batch.txt"
        out = subprocess.run([sys.executable, os.path.join(paths["source"], "examples",
                                                           "odometry.py"), folder,
                              "--trajectory", str(ours)], capture_output=True, text=True,
                             check=True)
        assert "refused" not in out.stdout and "median" in out.stdout
        from pnpba import batch

        assert batch.main([folder, "--output", str(tmp_path / "r.jsonl"), "--pairs", "within:1",
                           "--trajectory", str(batch_traj), "--quiet"]) == 0
        assert ours.read_text() == batch_traj.read_text()

        # Relocalisation against one key frame, described once: its depth's description kept,
        # and every frame's answer that of the pair estimated on its own.
        folder = os.path.join(paths["shared"], "tum_fr3_cabinet_keyframes")
        out = subprocess.run([sys.executable, os.path.join(paths["source"], "examples",
                                                           "relocalise.py"), folder, "--key", "0",
                              "--frames", "1-3"], capture_output=True, text=True, check=True)
        lines = out.stdout.splitlines()
        assert lines[-1].endswith("depth descriptions kept: 1"), out.stdout
        frames = pnpba.tum_frames(folder)
        camera = pnpba.tum_camera_for_folder(folder, "")["camera"]
        key = (cv2.imread(frames[0]["rgb"]), cv2.imread(frames[0]["depth"], cv2.IMREAD_UNCHANGED))
        for k, line in zip((1, 2, 3), lines):
            own = pnpba.estimate_two_view(*key, cv2.imread(frames[k]["rgb"]),
                                          cv2.imread(frames[k]["depth"], cv2.IMREAD_UNCHANGED),
                                          camera=camera)
            assert line.split()[:3] == ["0", "->", str(k)]
            assert line.split()[3] == (own.path if own.ok else "refused"), line
            if own.ok:
                turn = np.degrees(np.arccos(np.clip((np.trace(own.T[:3, :3]) - 1) / 2, -1, 1)))
                assert line.split()[4] == f"{turn:.1f}", line
