"""The Python package against the command line it must not drift from: the same images,
the same refusals with the same messages, the same per-scanline records.

The command line is conftest.py's: the binary crates/python/install.sh builds, or
``$CWISIM_BIN``.
"""

from __future__ import annotations

import json
import os
import pickle
import threading
import traceback

import numpy as np
import pytest
from conftest import cli

import cwisim

SCENES = list(cwisim.scenes())
RENDERERS = [r.name for r in cwisim.renderers()]


def test_the_embedded_scenes_and_renderers_are_the_command_line_s(tmp_path):
    listed = cli("scenes", cwd=tmp_path).stdout
    for name in SCENES:
        assert any(line.split()[0] == name for line in listed.splitlines() if line.strip())
    named = cli("renderers", cwd=tmp_path).stdout
    assert [line.split()[0] for line in named.splitlines() if line.strip()] == RENDERERS
    for name in SCENES:
        assert cwisim.scene(name) == json.loads(cli("scenes", name, cwd=tmp_path).stdout)


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("renderer", RENDERERS)
def test_every_image_is_the_command_line_s_npy_byte_for_byte(tmp_path, scene, renderer):
    """Each embedded scene by each renderer: the same values, bit for bit, or the same
    refusal with the same message."""
    out = cli("render", scene, "--renderer", renderer, "-q", "--npy", "a.npy", cwd=tmp_path)
    if out.returncode != 0:
        assert out.returncode == 2, out.stderr
        with pytest.raises(cwisim.UsageError) as refused:
            cwisim.render(scene, renderer)
        # the same message, its flags spoken as keyword arguments
        said = out.stderr.strip().removeprefix("error: ")
        assert str(refused.value) == cwisim._native.keyword_spelling(said)
        assert "--" not in str(refused.value), refused.value
        return
    r = cwisim.render(scene, renderer)
    expected = np.load(tmp_path / "a.npy")
    assert r.image.dtype == expected.dtype == np.float64
    assert r.image.shape == expected.shape
    assert r.image.tobytes() == expected.tobytes()


def test_the_records_are_the_stats_json_s(tmp_path):
    out = cli(
        "render", "still-life", "--renderer", "sbuffer", "-q", "--stats-json", "s.json",
        cwd=tmp_path,
    )
    assert out.returncode == 0, out.stderr
    stats = json.loads((tmp_path / "s.json").read_text())
    r = cwisim.render("still-life", "sbuffer")
    assert r.totals == stats["stats"]["totals"]
    assert r.counters == stats["counters"]
    assert r.line_period == stats["stats"]["line_period"]
    lines = stats["stats"]["lines"]
    assert len(r.lines) == len(lines) == r.height
    for field in ["busy_cycles", "stall_cycles", "ready", "deadline", "slack", "instructions"]:
        assert r.lines[field].tolist() == [line[field] for line in lines], field
    assert r.lines["Eval2"].tolist() == [line["opcodes"]["Eval2"] for line in lines]
    assert int(r.lines["late"].sum()) == r.totals["late_lines"]


def test_settings_take_python_values_and_the_command_line_s_spellings():
    a = cwisim.render("teapot-floor", size=(96, 96), shading="phong", aa="box-centre",
                      shade_tolerance=1 / 512, shadows=False)
    b = cwisim.render("teapot-floor", size="96x96", shading="PHONG", aa="box-centre",
                      shade_tolerance="0.001953125", shadows="off")
    assert a.image.tobytes() == b.image.tobytes()
    assert a.image.shape == (96, 96, 1)
    c = cwisim.render("teapot-floor", size=(96, 96), shading="phong", aa="box-centre")
    assert c.image.tobytes() != a.image.tobytes()  # its light casts the teapot's shadow
    assert cwisim.render("pot", shading=None).image.shape == (400, 400, 1)


def test_a_scene_as_python_data_draws_as_its_file(tmp_path):
    data = cwisim.scene("still-life")
    data["lights"][0]["shadows"] = False
    path = tmp_path / "mine.json"
    path.write_text(json.dumps(data))
    from_data = cwisim.render(data, size=(120, 80))
    from_file = cwisim.render(path, size=(120, 80))
    assert from_data.image.tobytes() == from_file.image.tobytes()
    assert from_file.scene == "mine"
    assert from_data.image.tobytes() != cwisim.render("still-life", size=(120, 80)).image.tobytes()


def test_bad_input_raises_the_located_error():
    with pytest.raises(cwisim.SceneError, match=r"missing field `height`"):
        cwisim.render({"kind": "world", "width": 8})
    data = cwisim.scene("still-life")
    data["meshes"][0]["vertices"][3] = [3, "x", -2]
    with pytest.raises(cwisim.SceneError) as bad:
        cwisim.render(data)
    # located in the scene as json.dumps(data, indent=2) prints it
    line = json.dumps(data, indent=2).splitlines()[int(str(bad.value).split(":")[0]) - 1]
    assert '"x"' in line, (str(bad.value), line)
    with pytest.raises(cwisim.UsageError, match=r"unknown renderer `nope`; known: vanrij"):
        cwisim.render("pot", "nope")
    with pytest.raises(cwisim.UsageError, match=r"unknown setting `colour`"):
        cwisim.render("pot", colour="red")
    with pytest.raises(cwisim.UsageError, match=r"^samples: expected a whole number"):
        cwisim.render("pot", "woo-chall", samples="three")
    with pytest.raises(cwisim.UsageError, match=r"no such scene file, and no embedded scene"):
        cwisim.render("no-such-scene")
    with pytest.raises(cwisim.UsageError, match=r"^numeric: "):
        cwisim.render("pot", numeric="f16")
    with pytest.raises(cwisim.UsageError, match=r"^size=\(60000, 60000\): the image would hold"):
        cwisim.render("pot", size=(60000, 60000))
    assert issubclass(cwisim.SceneError, cwisim.CwisimError)
    assert issubclass(cwisim.UsageError, cwisim.CwisimError)


def test_a_render_lets_other_python_threads_run():
    """The render runs without the GIL: a Python thread counts while it runs."""
    ticks = 0
    done = threading.Event()

    def count():
        nonlocal ticks
        while not done.is_set():
            ticks += 1

    t = threading.Thread(target=count)
    t.start()
    try:
        before = ticks
        cwisim.render("teapot", "woo-chall", samples=2)
        during = ticks - before
    finally:
        done.set()
        t.join()
    assert during > 1000


def test_frames_and_threads():
    r = cwisim.render("pot", "refine", threads=2)
    assert r.frames == 4 and r.image.shape == (4 * 400, 400, 1)
    assert np.shares_memory(r.frame(3), r.image)
    assert r.frame(3).tobytes() == cwisim.render("pot", "refine").frame(3).tobytes()
    with pytest.raises(IndexError):
        r.frame(4)


def test_ctrl_c_stops_a_render_after_a_scanline():
    """SIGINT during a render: KeyboardInterrupt, soon, naming the scanlines done."""
    import signal
    import time

    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt, match=r"cancelled after \d+ scanline"):
            cwisim.render("teapot", "woo-chall", samples=6, size=(1000, 1000))
    finally:
        timer.cancel()
    assert time.perf_counter() - start < 5.0


def test_progress_is_told_of_every_scanline_and_may_stop_the_render():
    told = []
    r = cwisim.render("pot", size=(64, 48), progress=lambda done, total: told.append((done, total)))
    assert told == [(k, 48) for k in range(1, 49)]
    assert r.image.shape == (48, 64, 1)
    frames = []
    cwisim.render("pot", "refine", size=(32, 24), progress=lambda d, t: frames.append(t))
    assert set(frames) == {4 * 24}

    class Enough(Exception):
        pass

    def stop(done, total):
        if done == 10:
            raise Enough(done)

    with pytest.raises(Enough):
        cwisim.render("pot", size=(64, 48), progress=stop)


def printed_rows(text: str):
    """The rows `cwisim render` prints: `(label, text)`, a text's continuation lines
    (indented to column 13) kept in it."""
    rows = []
    for line in text.splitlines():
        if line[:13].strip():
            rows.append([line[:13].strip(), line[13:]])
        elif line.strip() and rows:
            rows[-1][1] += "\n" + line
    return [tuple(r) for r in rows]


@pytest.mark.parametrize(
    "scene,renderer,more",
    [
        ("pot", "vanrij", {}),
        ("still-life", "sbuffer", {}),
        ("pot", "refine", {"size": (64, 48)}),
        ("fig25", "vanrij", {"numeric": "f32"}),
        ("fig25", "vanrij", {"numeric": "fixed:I=4.6,dI=4.6,ddI=1.6"}),
    ],
)
def test_the_summary_is_the_command_line_s(tmp_path, scene, renderer, more):
    """Row for row, label and text, but for the wall times and the files written."""
    args = ["render", scene, "--renderer", renderer, "-o", "x.png"]
    for k, v in more.items():
        args += [f"--{k}", v if isinstance(v, str) else f"{v[0]}x{v[1]}"]
    out = cli(*args, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    printed = [r for r in printed_rows(out.stdout) if r[0] not in ("time", "wrote")]
    r = cwisim.render(scene, renderer, **more)
    assert r.summary == printed
    labels = [label for label, _ in r.summary]
    assert labels[0] == "scene" and {"Y-processor", "instructions", "cycles", "worst line"} <= set(labels)
    if scene == "pot" and renderer == "vanrij":
        assert labels[:3] == ["scene", "geometry", "visibility"]
    if "numeric" in more:
        assert "overflows" in labels


@pytest.mark.parametrize("cls", [cwisim.CwisimError, cwisim.SceneError, cwisim.UsageError])
def test_the_errors_are_cwisim_s_and_pickle(cls):
    """They belong to the package (a traceback says `cwisim.UsageError`), and pickle, as a
    Dask worker sends them home."""
    assert cls.__module__ == "cwisim" and cls is getattr(cwisim, cls.__name__)
    e = cls("what went wrong, and where")
    back = pickle.loads(pickle.dumps(e))
    assert type(back) is cls and str(back) == str(e) and back.args == e.args
    said = "".join(traceback.format_exception_only(type(e), e))
    assert said.startswith(f"cwisim.{cls.__name__}: what went wrong")


def test_a_raised_error_pickles():
    with pytest.raises(cwisim.UsageError) as raised:
        cwisim.render("pot", "nope")
    back = pickle.loads(pickle.dumps(raised.value))
    assert type(back) is cwisim.UsageError and str(back) == str(raised.value)
    data = cwisim.scene("pot")
    del data["camera"]
    with pytest.raises(cwisim.SceneError) as raised:
        cwisim.render(data)
    back = pickle.loads(pickle.dumps(raised.value))
    assert type(back) is cwisim.SceneError and str(back) == str(raised.value)


def test_errors_name_keyword_arguments_not_flags():
    with pytest.raises(cwisim.UsageError) as refused:
        cwisim.render("pot", samples=4)
    assert str(refused.value).startswith("samples= is not used by vanrij"), refused.value
    assert "--" not in str(refused.value)
    with pytest.raises(cwisim.UsageError) as refused:
        cwisim.render("pot", aa="box", shading="phong")
    assert str(refused.value).startswith('aa="box" (exact) is not drawn with shading="phong"')
    assert 'use aa="box-centre"' in str(refused.value)
    with pytest.raises(cwisim.UsageError, match=r'^renderer="nishita" draws Bézier patches'):
        cwisim.render("pot", "nishita")
    with pytest.raises(cwisim.UsageError, match=r"^eval0_tolerance= is used with visibility="):
        cwisim.render("pot", eval0_tolerance=0.1)


@pytest.mark.parametrize("scene", [42, 1.5, b"pot", ["pot"]])
def test_a_scene_of_another_type_says_what_is_taken(scene):
    with pytest.raises(TypeError, match=r"^scene: expected an embedded scene's name, a scene file's path, or a dict"):
        cwisim.render(scene)
    with pytest.raises(TypeError, match=r"a dict"):
        cwisim.emit(scene)
    # the calls that read a scene file themselves (a dict is a UsageError there)
    for call in [cwisim.fit, cwisim.refine]:
        with pytest.raises(TypeError, match=r": expected an embedded scene's name or a scene file's path, not"):
            call(scene)


def test_a_value_of_the_wrong_form_says_what_is_expected():
    data = cwisim.scene("pot")
    data["meshes"][0]["material"]["k_d"] = "red"
    with pytest.raises(cwisim.SceneError) as bad:
        cwisim.render(data)
    message = str(bad.value)
    assert 'invalid type: string "red", expected a number, or a list of numbers (one per channel)' in message
    assert "variant" not in message
    # located in the scene as json.dumps(data, indent=2) prints it
    line = json.dumps(data, indent=2).splitlines()[int(message.split(":")[0]) - 1]
    assert '"k_d": "red"' in line, (message, line)
    data["meshes"][0]["material"]["k_d"] = [0.75]
    assert cwisim.render(data, size=(32, 32)).image.shape == (32, 32, 1)


def test_the_records_as_a_data_frame():
    r = cwisim.render("pot", size=(64, 48))
    df = r.lines_frame()
    assert len(df) == 48 and list(df.columns) == list(r.lines.dtype.names)
    assert df["busy_cycles"].tolist() == r.lines["busy_cycles"].tolist()
    assert int(df["late"].sum()) == r.totals["late_lines"]
