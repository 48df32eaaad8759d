# Paths the Python tests need, from the environment ctest sets (tests/CMakeLists.txt).
import os

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
