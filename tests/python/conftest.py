# Paths the Python tests need, from the environment ctest sets (tests/CMakeLists.txt).
import os
import subprocess

import pytest


@pytest.fixture(scope="session")
def paths():
    shared = os.environ.get("PNPBA_SHARED_DATA", "")
    return {
        "source": os.environ["PNPBA_SOURCE_DIR"],
        "shared": shared if os.path.isdir(shared) else None,
        "pose_cli": os.environ["PNPBA_POSE_CLI"],
        "bal_cli": os.environ["PNPBA_BAL_CLI"],
    }


@pytest.fixture
def cabinet_from_one_key_frame(paths, tmp_path):
    """Two rendered pairs of the cabinet by a wall from one key frame (frame 1 the same), camera 2
    turned 10 degrees and 0.25 m away, then 30 degrees and 0.5 m: too little texture for the
    features, so each pair registers the depths. Their folders (1.png, 1_depth.png, 2.png,
    2_depth.png, camera.yaml)."""
    render = os.path.join(os.path.dirname(paths["pose_cli"]), "render_synthetic")
    folders = []
    for deg, metres in (("10", "0.25"), ("30", "0.5")):
        folder = tmp_path / f"cabinet-{deg}"
        subprocess.run([render, "--output", str(folder), "--scene", "cabinet", "--kinect",
                        "--seed", "11", "--rotation-deg", deg, "--translation-m", metres],
                       check=True, capture_output=True)
        folders.append(folder)
    return folders
