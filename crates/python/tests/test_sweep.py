"""`tradeoff` from Python: the command line's rows, and the same rows from a Dask
cluster of two worker processes."""

from __future__ import annotations

import csv
import io
import os
import subprocess
import time
from pathlib import Path

import pytest

import cwisim
from cwisim import sweep

ROOT = Path(__file__).resolve().parents[3]
GRID = dict(size=(96, 96), renderers=["vanrij", "woo-chall", "sbuffer"], numeric=["f64", "f32"])


def cli_binary() -> Path:
    path = Path(os.environ.get("CWISIM_BIN", ROOT / "target" / "release" / "cwisim"))
    if not path.exists():
        pytest.fail(f"{path}: no cwisim binary; build it with `cargo build --release`")
    return path


@pytest.fixture(scope="module")
def local():
    return cwisim.tradeoff("still-life", repeat=1, **GRID)


def test_the_rows_are_the_command_line_s(tmp_path, local):
    out = subprocess.run(
        [str(cli_binary()), "tradeoff", "still-life", "--size", "96x96",
         "--renderers", "vanrij,woo-chall,sbuffer", "--numeric", "f64;f32",
         "--repeat", "1", "--csv", "t.csv"],
        cwd=tmp_path, capture_output=True, text=True, check=False,
    )
    assert out.returncode == 0, out.stderr
    rows = list(csv.DictReader(io.StringIO((tmp_path / "t.csv").read_text())))
    assert len(rows) == len(local) > 20
    for k, (theirs, ours) in enumerate(zip(rows, local)):
        for field, value in theirs.items():
            if field in ("host_ms",):
                continue
            if field.startswith("counter_"):
                mine = ours["counters"].get(field[len("counter_"):])
                assert value == ("" if mine is None else str(mine)), (k, field)
                continue
            mine = ours[field]
            if isinstance(mine, bool):
                assert value == str(mine).lower(), (k, field)
            elif isinstance(mine, float):
                assert float(value) == pytest.approx(mine, rel=1e-6, abs=1e-12), (k, field)
            else:
                assert value == ("" if mine is None else str(mine)), (k, field, value, mine)
    assert any(r["pareto"] for r in local)


def test_threads_give_the_same_rows(local):
    threaded = cwisim.tradeoff("still-life", repeat=1, threads=2, **GRID)
    assert sweep.compare(local, threaded) == []


def test_a_dask_cluster_of_two_workers_gives_the_local_rows(local):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        start = time.perf_counter()
        rows = cwisim.tradeoff("still-life", repeat=1, client=client, **GRID)
        elapsed = time.perf_counter() - start
        workers = {w for w in client.run(os.getpid).values()}
    assert len(workers) == 2
    assert sweep.compare(local, rows) == []
    print(f"\ndask: {len(rows)} rows on 2 workers in {elapsed:.2f} s")


def test_a_bad_sweep_is_refused_before_any_task():
    with pytest.raises(cwisim.UsageError, match="draws several frames"):
        cwisim.tradeoff("pot", renderers=["refine"])
    with pytest.raises(cwisim.UsageError, match="^numeric: "):
        cwisim.tradeoff("pot", numeric="f16")
    with pytest.raises(cwisim.UsageError, match="tradeoff takes a scene file"):
        cwisim.tradeoff(cwisim.scene("pot"))


def test_settings_times_scenes_here_and_on_dask():
    grid = dict(size=(48, 48), renderers=["vanrij"], numeric=["f64"], repeat=1)
    scenes = ["pot", "bowl"]
    rows = cwisim.tradeoff(scenes, **grid)
    alone = {name: cwisim.tradeoff(name, **grid) for name in scenes}
    # each scene's rows in turn, each as the scene's own sweep, its front its own
    assert [r["scene"] for r in rows] == [n for n in scenes for _ in alone[n]]
    for name in scenes:
        mine = [{k: v for k, v in r.items() if k != "scene"} for r in rows if r["scene"] == name]
        assert sweep.compare(alone[name], mine) == [], name
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        there = cwisim.tradeoff(scenes, client=client, **grid)
    assert sweep.compare(rows, there) == []
