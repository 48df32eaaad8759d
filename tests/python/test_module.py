"""The module reads well: documented, typed, and evaluate_tum reachable."""
import os

import pytest

import pnpba


def test_every_public_name_is_documented():
    assert pnpba.__doc__
    for name in pnpba.__all__:
        assert getattr(pnpba, name).__doc__, name


def test_type_stubs_are_shipped():
    folder = os.path.dirname(pnpba.__file__)
    assert os.path.isfile(os.path.join(folder, "_pnpba.pyi"))
    assert os.path.isfile(os.path.join(folder, "py.typed"))


def test_evaluate_tum_on_the_shared_sequence(paths):
    if paths["shared"] is None:
        pytest.skip("shared data not found (PNPBA_SHARED_DATA)")
    lines = []
    report = pnpba.evaluate_tum(os.path.join(paths["shared"], "tum_fr1_desk"), methods=["rgbd"],
                                max_gap=1, progress=lines.append)
    row = report["methods"][0]
    assert row["method"] == "rgbd" and row["pairs"] == len(report["pairs"]) == len(lines)
    # Ground truth: consecutive fr1_desk frames are estimated within 1 deg / 2 cm.
    assert row["median_rot_deg"] < 1.0 and row["median_trans_cm"] < 2.0
