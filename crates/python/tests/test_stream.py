"""Instruction streams: emitted, read and written in all three encodings, replayed —
against the command line's `emit` and `run`."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, cli

import cwisim

ENCODINGS = ["cwt", "jsonl", "cwb"]


def same(a: cwisim.Stream, b: cwisim.Stream, notes: bool = True) -> bool:
    """The same header and instructions (and notes, unless told: `.cwb` keeps none)."""
    fields = [f for f in a.instructions.dtype.names if notes or f != "note"]
    return (a.width, a.lines, a.channels) == (b.width, b.lines, b.channels) and all(
        a.instructions[f].tobytes() == b.instructions[f].tobytes() for f in fields
    ) and (not notes or a.notes == b.notes)


@pytest.mark.parametrize("scene,renderer", [("pot", "vanrij"), ("still-life", "sbuffer"), ("fig25", "vanrij")])
def test_a_stream_round_trips_through_every_encoding(tmp_path, scene, renderer):
    stream = cwisim.emit(scene, renderer)
    assert len(stream) > 0 and stream.instructions["op"][-1] == "Refresh"
    assert (stream.instructions["op"] == "Refresh").sum() == stream.lines
    for ext in ENCODINGS:
        path = tmp_path / f"s.{ext}"
        stream.write(path)
        assert same(cwisim.read_trace(path), stream, notes=ext != "cwb"), ext
        # the command line emits the same stream
        out = cli("emit", scene, "--renderer", renderer, "-o", f"cli.{ext}", cwd=tmp_path)
        assert out.returncode == 0, out.stderr
        assert same(cwisim.read_trace(tmp_path / f"cli.{ext}"), stream, notes=ext != "cwb"), ext


def test_a_replay_is_the_render_and_the_command_line_s_run(tmp_path):
    r = cwisim.render("still-life", "sbuffer")
    stream = cwisim.emit("still-life", "sbuffer")
    again = cwisim.replay(stream)
    assert again.image.tobytes() == r.image.tobytes()
    assert again.totals == r.totals
    assert again.lines.tobytes() == r.lines.tobytes()
    stream.write(tmp_path / "s.cwb")
    out = cli("run", "s.cwb", "--npy", "s.npy", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert np.load(tmp_path / "s.npy").tobytes() == r.image.tobytes()
    fixed = cwisim.replay(tmp_path / "s.cwb", numeric="fixed:I=10.14,dI=4.20,ddI=1.27")
    assert fixed.image.shape == r.image.shape and fixed.numeric.startswith("fixed:")
    assert fixed.image.tobytes() != r.image.tobytes()


def test_a_changed_stream_is_what_is_replayed(tmp_path):
    """Every value halved (NaN, in the slots not carried, stays NaN): the image halves,
    as the array is linear in its operands."""
    stream = cwisim.emit("fig25")
    for slot in ["I", "dI", "ddI"]:
        stream.instructions[slot] *= 0.5
    halved = cwisim.replay(stream).image
    whole = cwisim.render("fig25").image
    assert whole.max() > 0
    assert np.allclose(halved, whole * 0.5, rtol=0, atol=1e-12)


def test_bad_traces_and_streams_are_refused_located(tmp_path):
    bad = tmp_path / "bad.cwt"
    bad.write_text("cwisim-trace version=1 width=4 lines=1 channels=1\nEval1 0 9 0.5\nRefresh\n")
    with pytest.raises(cwisim.SceneError, match=r"bad\.cwt:2"):
        cwisim.read_trace(bad)
    with pytest.raises(cwisim.SceneError, match=r"bad\.cwt:2"):
        cwisim.replay(bad)
    stream = cwisim.emit("fig25")
    stream.instructions["x"][3] = 10_000
    with pytest.raises(cwisim.UsageError, match=r"^instruction 3 \("):
        stream.write(tmp_path / "x.cwb")
    assert not (tmp_path / "x.cwb").exists()
    stream = cwisim.emit("fig25")
    stream.instructions["op"][0] = "Jump"
    with pytest.raises(cwisim.UsageError, match="no opcode is called 'Jump'"):
        stream.write(tmp_path / "x.cwb")
    with pytest.raises(cwisim.UsageError, match="unknown trace encoding `txt`"):
        cwisim.emit("fig25").write(tmp_path / "x.txt")
    (tmp_path / "target.cwb").write_bytes(b"kept")
    (tmp_path / "link.cwb").symlink_to(tmp_path / "target.cwb")
    with pytest.raises(cwisim.UsageError, match="not a regular file"):
        cwisim.emit("fig25").write(tmp_path / "link.cwb")
    assert (tmp_path / "target.cwb").read_bytes() == b"kept"
    with pytest.raises(cwisim.UsageError, match="previous frame"):
        cwisim.emit("pot", "refine")


def test_a_pixel_s_history_is_the_command_line_s(tmp_path):
    trace = ROOT / "traces" / "visibility.cwt"
    out = cli("history", str(trace), "--x", "9", "--line", "0", "--all", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    printed = [line.split() for line in out.stdout.splitlines() if line.startswith("cycle")]
    visits = cwisim.history(trace, 9, 0)
    assert [(int(p[1]), p[2], p[3]) for p in printed] == [
        (v["cycle"], f"#{v['index']}", v["op"]) for v in visits
    ]
    assert visits[0]["note"] == "passes through" and not visits[0]["addressed"]
    assert visits[2]["after"]["acc"] == [0.375] and visits[2]["before"]["acc"] == [0.0]
    assert visits[0]["provenance"].startswith("near object")
    # a Stream's history is its file's
    same = cwisim.history(cwisim.read_trace(trace), 9, 0)
    assert [(v["cycle"], v["after"]) for v in same] == [(v["cycle"], v["after"]) for v in visits]
    with pytest.raises(cwisim.UsageError, match="line 99: the trace outputs"):
        cwisim.history(trace, 9, 99)
    with pytest.raises(cwisim.UsageError, match="x 99: the trace has processors"):
        cwisim.history(trace, 99, 0)


def parse_vcd(text: str):
    """A Value Change Dump's signals as `scope.name` → [(time, value)] (what cwisim vcd
    writes: real, wire and bit values; `z` as NaN)."""
    ids, scopes, out, now = {}, [], {}, None
    body = False
    for tok in text.split("\n"):
        tok = tok.strip()
        if tok.startswith("$scope module"):
            scopes.append(tok.split()[2])
        elif tok.startswith("$upscope"):
            scopes.pop()
        elif tok.startswith("$var"):
            _, _, _, code, name, _ = tok.split()
            ids[code] = f"{scopes[-1]}.{name}"
            out[ids[code]] = []
        elif tok.startswith("$enddefinitions"):
            body = True
        elif body and tok.startswith("#"):
            now = int(tok[1:])
        elif body and tok and not tok.startswith("$"):
            if tok[0] in "rb":
                value, code = tok[1:].split()
                v = float("nan") if value == "z" else (float(value) if tok[0] == "r" else int(value, 2))
            else:
                value, code = tok[0], tok[1:]
                v = float("nan") if value == "z" else int(value)
            out[ids[code]].append((now, v))
    return out


def test_a_waveform_is_the_command_line_s_vcd(tmp_path):
    trace = ROOT / "traces" / "gouraud.cwt"
    out = cli("vcd", str(trace), "--line", "1", "--x", "2..=8", "-o", "l.vcd", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    dumped = parse_vcd((tmp_path / "l.vcd").read_text())
    wave = cwisim.waveform(trace, 1, (2, 8))
    assert set(wave.signals) == set(dumped)
    for name, changes in dumped.items():
        cycles, values = wave.signals[name]
        assert cycles.tolist() == [t for t, _ in changes], name
        assert np.array_equal(values, np.array([v for _, v in changes], dtype=float), equal_nan=True), name
    assert wave.start == dumped["bus.opcode"][0][0]
    every, acc = wave.sampled("p5.acc")
    assert len(every) == wave.end - wave.start + 1 and acc[-1] == wave.signals["p5.acc"][1][-1]
    # the whole array by default (16 processors), one processor, a range
    assert "p15.acc" in cwisim.waveform(trace, 1).signals
    assert {n.split(".")[0] for n in cwisim.waveform(trace, 1, 4).signals} == {"bus", "p4"}
    assert "p7.out" in cwisim.waveform(trace, 1, range(6, 8)).signals
    with pytest.raises(cwisim.UsageError, match="processors 2..=99"):
        cwisim.waveform(trace, 1, (2, 99))


def test_notes_say_where_each_instruction_came_from(tmp_path):
    stream = cwisim.emit("fig25")
    assert stream.notes and (stream.instructions["note"] >= 0).any()
    first = int(np.flatnonzero(stream.instructions["note"] >= 0)[0])
    assert stream.note(first).startswith("row ")
    # the command line's .cwt carries the same notes on the same instructions
    out = cli("emit", "fig25", "-o", "cli.cwt", cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert same(cwisim.read_trace(tmp_path / "cli.cwt"), stream)
    assert cwisim.read_trace(tmp_path / "cli.cwt").notes == stream.notes
    for ext in ["cwt", "jsonl"]:
        stream.write(tmp_path / f"n.{ext}")
        back = cwisim.read_trace(tmp_path / f"n.{ext}")
        assert same(back, stream) and back.notes == stream.notes, ext
    stream.write(tmp_path / "n.cwb")  # the binary form has no place for notes
    bare = cwisim.read_trace(tmp_path / "n.cwb")
    assert (bare.instructions["note"] == -1).all() and bare.notes == []
    # a Stream's history keeps its provenance
    visits = cwisim.history(stream, 5, 6)
    assert any(v["provenance"] for v in visits)
