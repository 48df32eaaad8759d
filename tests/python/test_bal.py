"""pnpba.read_bal / solve_bal: the same final cost as bundle_adjust_bal, in-place updates,
the per-iteration callback, and errors that name the file."""
import json
import os
import subprocess

import numpy as np
import pytest

import pnpba


@pytest.fixture
def dubrovnik(paths):
    if paths["shared"] is None:
        pytest.skip("shared data not found (PNPBA_SHARED_DATA)")
    return os.path.join(paths["shared"], "bal", "dubrovnik-3-7-pre.txt")


def test_same_final_cost_as_the_cli(paths, dubrovnik, tmp_path):
    out = tmp_path / "summary.json"
    subprocess.run([paths["bal_cli"], dubrovnik, "--iterations", "20", "--json", str(out)],
                   check=True, capture_output=True)
    cli = json.loads(out.read_text())

    problem = pnpba.read_bal(dubrovnik)
    assert problem.cameras.shape == (3, 9) and problem.points.shape == (7, 3)
    before = problem.points.copy()
    rows = []
    summary = pnpba.solve_bal(problem, iterations=20, callback=rows.append)
    assert summary.final_cost == pytest.approx(cli["final_cost"], rel=1e-9)
    assert summary.initial_cost == pytest.approx(cli["initial_cost"], rel=1e-12)
    assert summary.final_cost < summary.initial_cost
    # The problem was solved in place: its own cost is the summary's, its points moved.
    assert problem.cost() == pytest.approx(summary.final_cost, rel=1e-9)
    assert not np.array_equal(before, problem.points)
    # One callback row per table row, the initial cost first.
    assert [r["iteration"] for r in rows] == [r["iteration"] for r in summary.table]
    assert rows[0]["cost"] == summary.initial_cost


def test_views_write_through(dubrovnik):
    problem = pnpba.read_bal(dubrovnik)
    cost = problem.cost()
    problem.points[0] += 1.0  # a view of the problem's own memory
    assert problem.cost() != cost
    assert problem.observations.shape == (problem.num_observations, 2)
    assert problem.camera_index.max() < problem.num_cameras


def test_callback_exception_is_raised_after_the_solve(dubrovnik):
    problem = pnpba.read_bal(dubrovnik)

    def stop(_row):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        pnpba.solve_bal(problem, iterations=5, callback=stop)


def test_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("1 1 1\n0 0 nan 2\n")
    with pytest.raises(pnpba.Error, match="bad.txt:2: observation u: non-finite value 'nan'"):
        pnpba.read_bal(str(bad))
    with pytest.raises(pnpba.Error, match="cannot open"):
        pnpba.read_bal(str(tmp_path / "missing.txt"))


def test_bad_solver_options_raise(dubrovnik):
    problem = pnpba.read_bal(dubrovnik)
    with pytest.raises(pnpba.Error, match="solver"):
        pnpba.solve_bal(problem, solver="magic")
