"""`fit` from Python: the command line's registers, for the same scene and budget."""

from __future__ import annotations

import os

import pytest
from conftest import cli

import cwisim


def test_fit_finds_the_command_line_s_registers(tmp_path):
    out = cli("fit", "fig25", "--max-error", "1/256", "--threads", "1", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    printed = dict(
        (line[:16].strip(), line[16:].strip()) for line in out.stdout.splitlines() if line[:16].strip()
    )
    found = cwisim.fit("fig25", max_error=1 / 256, threads=1)
    assert printed["registers"] == found["numeric"]
    assert printed["replays"] == str(found["replays"])
    assert found["error"] <= 1 / 256
    assert found["bits"] == sum(i + f for i, f, _ in found["registers"].values())
    # the format found draws the scene within the budget of the f64 array
    exact = cwisim.render("fig25").image
    narrow = cwisim.render("fig25", numeric=found["numeric"]).image
    assert abs(narrow - exact).max() <= 1 / 256


def test_a_budget_out_of_reach_is_refused():
    with pytest.raises(cwisim.UsageError, match="max_error"):
        cwisim.fit("fig25", max_error=0)
    with pytest.raises(cwisim.UsageError, match="overflow: unknown"):
        cwisim.fit("fig25", overflow="clip")


def test_refine_measures_the_command_line_s_phases(tmp_path):
    out = cli("refine", "still-life", "--size", "120x80", "--csv", "r.csv", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    import csv

    printed = list(csv.DictReader((tmp_path / "r.csv").open()))
    run = cwisim.refine("still-life", size=(120, 80))
    ours = [("refine", r) for r in run["phases"]] + [("naive", r) for r in run["naive"]]
    assert len(printed) == len(ours)
    for row, (sequence, r) in zip(printed, ours):
        assert row["sequence"] == sequence and row["phase"] == r["phase"]
        for field in ["pixels", "instructions", "regenerated", "busy_cycles", "late_lines"]:
            assert int(row[field]) == r[field], (r["phase"], field)
        assert float(row["rms"]) == pytest.approx(r["rms"], rel=1e-9, abs=1e-15)
    # still-life's main light casts shadows: the shadow phase follows flat
    assert [r["phase"] for r in run["phases"]][:2] == ["flat", "shadows"]
    assert run["frames"].shape == (len(run["phases"]), 80, 120, 3)
    assert run["busy_per_line"].shape == (len(run["phases"]), 80)
    assert run["busy_per_line"][0].sum() == run["phases"][0]["busy_cycles"]
    with pytest.raises(cwisim.UsageError, match="is not used by refine"):
        cwisim.refine("pot", samples=3)
    with pytest.raises(cwisim.UsageError, match="unknown phase"):
        cwisim.refine("pot", phases="flat,glow")


@pytest.mark.parametrize(
    "call",
    [
        lambda: cwisim.fit("pot", size=(1600, 1600), max_error=1 / 4096, threads=1),
        lambda: cwisim.refine("teapot", size=(1000, 1000)),
    ],
    ids=["fit", "refine"],
)
def test_ctrl_c_stops_a_long_call(call):
    """SIGINT during fit or refine: KeyboardInterrupt soon, the work stopped."""
    import signal
    import threading
    import time

    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    assert time.perf_counter() - start < 6.0
