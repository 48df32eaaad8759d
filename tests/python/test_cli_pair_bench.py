# bench/cli_pair_bench.py: one CLI process per pair, beside an anchor build, summarised per set.
import json
import os
import subprocess
import sys

import pytest


def test_cli_pair_bench_summarises_each_build_and_their_paired_difference(paths, tmp_path):
    if paths["shared"] is None:
        pytest.skip("no shared data")
    build = os.path.dirname(os.path.dirname(paths["pose_cli"]))
    out = tmp_path / "cli.json"
    subprocess.run([sys.executable, os.path.join(paths["source"], "bench", "cli_pair_bench.py"),
                    "--shared", paths["shared"], "--build", build, "--anchor", paths["pose_cli"],
                    "--sets", "fr1_desk", "--pairs", "3", "--rounds", "2", "--json", str(out)],
                   check=True, stdout=subprocess.DEVNULL)
    (row,) = json.loads(out.read_text())["sets"]
    assert row["name"] == "fr1_desk" and row["runs"] == 6
    for label in ("build", "anchor"):
        for kind in ("in_process", "wall"):
            s = row[label][kind]
            assert 0 < s["p50_ms"] <= s["p95_ms"] <= s["max_ms"]
        # A whole run takes longer than its estimate.
        assert row[label]["wall"]["p50_ms"] > row[label]["in_process"]["p50_ms"]
    assert set(row["paired_median_ms"]) == {"in_process", "wall"}


@pytest.mark.parametrize("sets, message", [
    ("nope", "unknown set 'nope'"),
    ("fr1_desk", "/nonexistent/tum_fr1_desk: no such folder"),
])
def test_cli_pair_bench_names_what_it_cannot_use(paths, sets, message):
    build = os.path.dirname(os.path.dirname(paths["pose_cli"]))
    done = subprocess.run([sys.executable, os.path.join(paths["source"], "bench",
                                                         "cli_pair_bench.py"),
                           "--shared", "/nonexistent", "--build", build, "--sets", sets],
                          capture_output=True, text=True)
    assert done.returncode != 0 and message in done.stderr
