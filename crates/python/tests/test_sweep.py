"""`tradeoff` from Python: the command line's rows, and the same rows from a Dask
cluster of two worker processes."""

from __future__ import annotations

import csv
import io
import json
import os
import time

import pytest
from conftest import cli

import cwisim
from cwisim import sweep

GRID = dict(size=(96, 96), renderers=["vanrij", "woo-chall", "sbuffer"], numeric=["f64", "f32"])


@pytest.fixture(scope="module")
def local():
    return cwisim.tradeoff("still-life", repeat=1, **GRID)


def test_the_rows_are_the_command_line_s(tmp_path, local):
    out = cli(
        "tradeoff", "still-life", "--size", "96x96", "--renderers", "vanrij,woo-chall,sbuffer",
        "--numeric", "f64;f32", "--repeat", "1", "--csv", "t.csv", cwd=tmp_path,
    )
    assert out.returncode == 0, out.stderr
    rows = list(csv.DictReader(io.StringIO((tmp_path / "t.csv").read_text())))
    assert len(rows) == len(local) > 20
    for k, (theirs, ours) in enumerate(zip(rows, local)):
        # where the row stands in the sweep, for `tradeoff --merge` (the CSV's own)
        assert (theirs["setting"], theirs["settings"]) == (str(k), str(len(rows)))
        assert theirs["sweep"].startswith("still-life:")
        for field, value in theirs.items():
            if field in ("host_ms", "sweep", "setting", "settings"):
                continue
            if field in cwisim.NOT_APPLICABLE:
                # the CSV's `-` is None
                assert value == ("-" if ours[field] is None else ours[field]), (k, field)
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
    with pytest.raises(cwisim.UsageError, match="draws several frames") as refused:
        cwisim.tradeoff("pot", renderers=["refine"])
    # a command it quotes is the command line's, as written
    assert "`cwisim render --renderer refine` prints its phases" in str(refused.value)
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


def test_what_does_not_apply_is_none(local):
    """`-` nowhere: a field that does not apply to a row is None, in every column."""
    assert not [(k, f) for k, r in enumerate(local) for f, v in r.items() if v == "-"]
    woo = [r for r in local if r["renderer"] == "woo-chall"]
    assert woo and all(r["aa"] is None and r["samples"] >= 1 for r in woo)
    van = [r for r in local if r["renderer"] == "vanrij"]
    assert van and all(r["aa"] is not None and r["samples"] is None for r in van)
    fig = cwisim.tradeoff("fig25", repeat=1, renderers=["vanrij"], numeric="f64")
    assert all(r["shadows"] is None and r["visibility"] is None for r in fig)


def test_a_renderer_left_out_is_a_warning_as_the_command_line_says(tmp_path):
    grid = dict(size=(32, 32), numeric="f64", repeat=1)
    with pytest.warns(cwisim.TradeoffWarning) as told:
        rows = cwisim.tradeoff("pot", **grid)
    out = cli("tradeoff", "pot", "--size", "32x32", "--numeric", "f64", "--repeat", "1", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    skipped = [line for line in out.stdout.splitlines() if line.startswith("skipped ")]
    assert skipped and [str(w.message) for w in told] == skipped
    assert skipped[0].startswith("skipped nishita: the scene has no Bézier patches")
    assert "nishita" not in {r["renderer"] for r in rows}


def test_the_rows_as_a_data_frame(local):
    df = cwisim.frame(local)
    assert len(df) == len(local) and "counters" not in df.columns
    assert df["busy_cycles"].tolist() == [r["busy_cycles"] for r in local]
    assert df["pareto"].tolist() == [r["pareto"] for r in local]


def test_an_error_on_a_dask_worker_comes_home_as_itself():
    """A worker's cwisim error pickles: the client raises the same class and message."""
    distributed = pytest.importorskip("dask.distributed")
    args = cwisim._plan_args("pot", (32, 32), None, None, ["vanrij"], "f64", None)
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        with pytest.raises(cwisim.UsageError, match=r"^group 99 of a plan of \d+"):
            client.submit(sweep.measure_group, args, 99, 1, pure=False).result()


def test_sbuffer_s_a_buffer_and_nishita_s_normal_angle_are_axes_as_on_the_command_line(tmp_path):
    rows = cwisim.tradeoff(
        "pot", size=(32, 32), renderers="sbuffer", sbuffer=["host", "abuffer"], numeric="f64", repeat=1
    )
    # per shading, the samples axis once for each mode; the A-buffer's shown in `aa`
    assert len(rows) == 24
    assert sum(r["aa"] == "abuffer" for r in rows) == 12
    # one bicubic dome (crates/host/tests/common's patch scene, its front patch)
    patches = tmp_path / "patches.json"
    vertices = []
    for j in range(4):
        for i in range(4):
            bump = 1.2 if 1 <= i <= 2 and 1 <= j <= 2 else 0.0
            vertices.append([2.0 * (i - 1.5) / 3.0, 2.0 * (j - 1.5) / 3.0, bump])
    patches.write_text(json.dumps({
        "kind": "world", "width": 32, "height": 32, "channels": 1,
        "camera": {"eye": [0.3, 0.4, 5], "target": [0.2, 0, 0], "up": [0, 1, 0], "fov_y": 40},
        "ambient": 0.2, "lights": [{"position": [2, 3, 6], "intensity": 0.8}],
        "meshes": [{"material": {"k_a": 0.4, "k_d": 0.7, "k_s": 0.6, "n": 20}, "two_sided": True,
                    "bezier": {"tessellate": 3, "vertices": vertices, "patches": [list(range(16))]}}],
    }))
    rows = cwisim.tradeoff(str(patches), renderers="nishita", normal_angle=["off", 10], numeric="f64", repeat=1)
    assert [r["normal_angle"] for r in rows] == [None, None, 10.0, 10.0] * 3
    out = cli(
        "tradeoff", str(patches), "--renderers", "nishita", "--normal-angle", "off,10",
        "--numeric", "f64", "--repeat", "1", "--csv", "na.csv", cwd=tmp_path,
    )
    assert out.returncode == 0, out.stderr
    theirs = list(csv.DictReader(io.StringIO((tmp_path / "na.csv").read_text())))
    assert [r["normal_angle"] for r in theirs] == ["" if r["normal_angle"] is None else "10" for r in rows]
    assert [int(r["instructions"]) for r in theirs] == [r["instructions"] for r in rows]
    with pytest.raises(cwisim.UsageError, match="normal_angle: expected a number of degrees or off"):
        cwisim.tradeoff(str(patches), normal_angle="sharp")
    with pytest.raises(cwisim.UsageError, match="between 0.5 and 180 degrees"):
        cwisim.tradeoff(str(patches), renderers="nishita", normal_angle=200)
    with pytest.raises(cwisim.UsageError, match="^sbuffer: "):
        cwisim.tradeoff("pot", renderers="sbuffer", sbuffer="everything")
