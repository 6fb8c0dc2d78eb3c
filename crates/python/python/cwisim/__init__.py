"""cwisim in Python: a cycle-level simulator of the CWI display architecture.

Scenes in, NumPy out. The drawing settings keep the command line's names
(``shade_tolerance`` for ``--shade-tolerance``) and spellings; errors are exceptions
carrying the command line's located message. docs/PYTHON.md documents the API.

>>> import cwisim
>>> r = cwisim.render("pot")
>>> r.image.shape
(400, 400, 1)
>>> int(r.lines["late"].sum())
0
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from ._native import CwisimError, SceneError, UsageError

__all__ = [
    "CwisimError",
    "SceneError",
    "UsageError",
    "Render",
    "RendererInfo",
    "render",
    "renderers",
    "scene",
    "scenes",
    "setting_names",
    "tradeoff",
    "mark_pareto",
    "TradeoffWarning",
    "frame",
    "Stream",
    "emit",
    "read_trace",
    "replay",
    "fit",
    "refine",
    "history",
    "Waveform",
    "waveform",
]

#: A scene: an embedded scene's name or a scene file's path (``None``: the default,
#: ``pot``), or the scene itself as Python data (the JSON scene as dicts and lists).
SceneLike = Union[str, "os.PathLike[str]", Mapping[str, Any], None]


class TradeoffWarning(UserWarning):
    """A renderer :func:`tradeoff` leaves out of its grid, and why (the command line's
    ``skipped nishita: …``)."""


def scenes() -> Dict[str, str]:
    """The embedded scenes: name → one line about it, in ``cwisim scenes``' order."""
    return dict(_native.scenes())


def scene(name: str) -> Dict[str, Any]:
    """The embedded scene ``name`` as Python data (what ``cwisim scenes NAME`` prints),
    ready to change and pass to :func:`render`."""
    return json.loads(_native.scene_text(name))


@dataclass(frozen=True)
class RendererInfo:
    """A registered renderer: its name, one line about it, and the settings it reads
    (by their Python names); :func:`render` refuses any other setting for it."""

    name: str
    about: str
    settings: Tuple[str, ...]


def renderers() -> List[RendererInfo]:
    """The registered renderers, in ``cwisim renderers``' order."""
    return [RendererInfo(n, a, tuple(s)) for n, a, s in _native.renderers()]


def setting_names() -> List[str]:
    """Every drawing setting's Python name, in the command line's order."""
    return list(_native.setting_names())


@dataclass
class Render:
    """What :func:`render` gives back.

    ``image``: the array's output, ``float64``, shape ``(scanlines, width, channels)``
    (every frame's scanlines, top to bottom; the same values as ``cwisim render --npy``).
    ``lines``: one record per scanline (a NumPy structured array: ``line``, ``frame``,
    ``row``, ``instructions``, ``busy_cycles``, ``stall_cycles``, ``first_issue``,
    ``ready``, ``deadline``, ``slack``, ``late``, ``overflows``, ``suppressed``, … and a
    count per opcode, ``SetI`` … ``Nop``). ``counters``: the renderer's own figures by
    name; ``totals``: the array's (instructions, cycles, late lines, …); ``summary``: the
    rows ``(label, text)`` of the summary ``cwisim render`` prints, but for its wall
    times (``time``) and the files it wrote (``wrote``): ``scene``, the renderer's own
    rows (``geometry``, ``visibility``, …), ``Y-processor`` (its counters),
    ``instructions``, ``cycles``, ``worst line``, and ``late`` and ``overflows`` when they
    apply. A text of several lines continues as the command line prints it, indented to
    column 13: ``print(f"{label:12} {text}")`` prints the rows as it does.
    """

    image: np.ndarray
    lines: np.ndarray
    counters: Dict[str, int]
    totals: Dict[str, Any]
    machine: Dict[str, Any]
    summary: List[Tuple[str, str]]
    renderer: str
    phrase: str
    scene: str
    kind: str
    width: int
    height: int
    channels: int
    frames: int
    line_period: int
    numeric: str
    settings: Dict[str, str] = field(default_factory=dict)

    def frame(self, k: int) -> np.ndarray:
        """Frame ``k``'s image, ``(height, width, channels)`` (a view, not a copy)."""
        if not 0 <= k < self.frames:
            raise IndexError(f"frame {k} of a render of {self.frames} frame(s)")
        return self.image[k * self.height : (k + 1) * self.height]

    def lines_frame(self):
        """The per-scanline records as a pandas DataFrame, a row per scanline (pandas:
        installed by ``crates/python/install.sh``; not needed by the rest of cwisim)."""
        return _pandas().DataFrame(self.lines)

    def __repr__(self) -> str:
        late = int(self.lines["late"].sum()) if len(self.lines) else 0
        return (
            f"<cwisim.Render {self.scene} by {self.renderer}: {self.width}×{self.height}"
            f"×{self.channels}, {self.frames} frame(s), "
            f"{self.totals.get('instructions', 0)} instructions, {late} late scanline(s)>"
        )


def _spelled(name: str, value: Any) -> str:
    """A setting's value as the command line spells it."""
    if isinstance(value, bool):
        if name == "shadows":
            return "on" if value else "off"
        return "true" if value else "false"
    if name == "size" and isinstance(value, (tuple, list)) and len(value) == 2:
        return f"{int(value[0])}x{int(value[1])}"
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _pandas():
    """pandas, or an ImportError saying how to install it."""
    try:
        import pandas  # noqa: PLC0415 (optional)
    except ImportError as e:
        raise ImportError(
            "cwisim's DataFrames need pandas: `python3 -m pip install pandas` "
            "(crates/python/install.sh installs it)"
        ) from e
    return pandas


def _where(scene: SceneLike) -> Dict[str, Any]:
    """The native module's arguments naming a scene."""
    if scene is not None and not isinstance(scene, (str, os.PathLike, Mapping)):
        raise TypeError(
            "scene: expected an embedded scene's name, a scene file's path, or a dict "
            f"(the scene as Python data, as cwisim.scene(name) gives), not {type(scene).__name__}"
        )
    if isinstance(scene, Mapping):
        # indented, so that a located error's line and column point into
        # json.dumps(scene, indent=2)
        return {"scene_json": json.dumps(scene, indent=2), "name": str(scene.get("name", "scene"))}
    return {"scene": _path(scene)}


def _given(settings: Mapping[str, Any]) -> List[Tuple[str, str]]:
    """The settings given (``None``: left at the default), spelled for the native module."""
    return [(k, _spelled(k, v)) for k, v in settings.items() if v is not None]


def _path(path: Optional[Union[str, "os.PathLike[str]"]]) -> Optional[str]:
    return None if path is None else os.fspath(path)


def _named(scene: SceneLike, what: str) -> Optional[str]:
    """A scene named by a file or an embedded name, for the calls that read it themselves
    (every task of a sweep, every replay of a fit)."""
    if isinstance(scene, Mapping):
        raise UsageError(
            f"{what} takes a scene file or an embedded scene's name (write a dict to a file first)"
        )
    if scene is not None and not isinstance(scene, (str, os.PathLike)):
        raise TypeError(
            f"{what}: expected an embedded scene's name or a scene file's path, "
            f"not {type(scene).__name__}"
        )
    return _path(scene)


@contextlib.contextmanager
def _written(stream: "Stream", encoding: str = "cwb"):
    """``stream`` as a temporary trace file, for the calls that read one (``.cwb``, or
    ``.jsonl`` to keep the notes)."""
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / f"stream.{encoding}"
        stream.write(path)
        yield path


def render(
    scene: SceneLike = None,
    renderer: str = "vanrij",
    *,
    numeric: str = "f64",
    timing: str = "fast",
    machine: Optional[Union[str, "os.PathLike[str]"]] = None,
    threads: int = 1,
    progress: Optional[Callable[[int, int], Any]] = None,
    **settings: Any,
) -> Render:
    """Draws ``scene`` with ``renderer`` and runs the instructions through the simulated
    X-processor array, as ``cwisim render`` does.

    ``scene``: an embedded scene's name (:func:`scenes`), a scene file's path, or the
    scene as Python data (a dict, as :func:`scene` returns). ``renderer``: a name from
    :func:`renderers`. ``numeric``: the array's registers (``"f64"``, ``"f32"``,
    ``"fixed:I=…"``); ``timing``: ``"fast"`` or ``"stepped"`` (the same results);
    ``machine``: a machine model JSON file; ``threads``: as ``--threads`` (the results are
    the same at any count). Every other keyword is a drawing setting by its Python name,
    valued as on the command line (``shading="phong"``, ``aa="box-centre"``,
    ``samples=4``, ``size=(640, 480)`` or ``"640x480"``, ``shadows=True`` or ``"on"``);
    ``None`` leaves a setting at its default. A setting the renderer does not read, or
    that the others leave idle, raises :class:`UsageError` naming what would use it.

    ``progress``: called after each scanline with (scanlines done, scanlines in all) —
    a progress bar's ``update`` (an exception it raises stops the render, and is raised).
    Runs without the GIL. Raises :class:`SceneError` for a scene that cannot be read (the
    message locates it) and :class:`UsageError` for names, settings or sizes refused.
    """
    given = _given(settings)
    out = _native.render(
        **_where(scene),
        renderer=renderer,
        settings=given,
        numeric=numeric,
        timing=timing,
        machine=_path(machine),
        threads=threads,
        progress=progress,
    )
    return _render_of(out, settings=dict(given))


def _render_of(out: Mapping[str, Any], **more: Any) -> Render:
    """A :class:`Render` from the native module's dict."""
    return Render(
        image=out["image"],
        lines=_records(out["lines"]),
        counters=dict(out.get("counters", {})),
        totals=json.loads(out["totals"]),
        machine=json.loads(out["machine"]),
        summary=[tuple(r) for r in out.get("summary", [])],
        renderer=out.get("renderer", "-"),
        phrase=out.get("phrase", ""),
        scene=out.get("scene", "-"),
        kind=out.get("kind", "trace"),
        width=out["width"],
        height=out["height"],
        channels=out["channels"],
        frames=out["frames"],
        line_period=out["line_period"],
        numeric=out["numeric"],
        **more,
    )


def _records(columns: Mapping[str, np.ndarray]) -> np.ndarray:
    """Named columns of equal length as one structured array."""
    names = list(columns)
    n = len(columns[names[0]]) if names else 0
    out = np.empty(n, dtype=[(k, columns[k].dtype) for k in names])
    for k in names:
        out[k] = columns[k]
    return out


def _plan_args(
    scene, size, tessellate, shadows, renderers, numeric, machine, sbuffer=None, normal_angle=None
) -> Dict[str, Any]:
    """The arguments of a tradeoff plan, as plain (picklable) Python values."""
    scene = _named(scene, "tradeoff")
    if size is not None and not isinstance(size, str):
        size = f"{int(size[0])}x{int(size[1])}"
    if isinstance(shadows, bool):
        shadows = [shadows]
    if isinstance(numeric, str):
        numeric = [numeric]
    if isinstance(renderers, str):
        renderers = [renderers]
    if isinstance(sbuffer, str):
        sbuffer = [sbuffer]
    if normal_angle is not None and not isinstance(normal_angle, (list, tuple)):
        normal_angle = [normal_angle]
    return {
        "scene": scene,
        "size": size,
        "tessellate": list(_native.default_tessellations() if tessellate is None else tessellate),
        "shadows": [bool(v) for v in (shadows or [])],
        "renderers": list(renderers or []),
        "numeric": list(_native.default_formats() if numeric is None else numeric),
        "sbuffer": list(sbuffer or []),
        "normal_angle": [_angle_or_off(a) for a in (normal_angle or [])],
        "machine": _path(machine),
    }


def _angle_or_off(value: Any) -> Optional[float]:
    """A ``normal_angle`` value: degrees, or ``None``/``"off"`` (the test not made)."""
    if value is None or (isinstance(value, str) and value.strip().lower() == "off"):
        return None
    try:
        return float(value)
    except (TypeError, ValueError):
        raise UsageError(f"normal_angle: expected a number of degrees or off, found {value!r}") from None


def tradeoff(
    scene: Union[SceneLike, Sequence[Union[str, "os.PathLike[str]"]]] = None,
    *,
    size: Optional[Union[str, Tuple[int, int]]] = None,
    tessellate: Optional[List[int]] = None,
    shadows: Optional[Union[bool, List[bool]]] = None,
    renderers: Optional[List[str]] = None,
    numeric: Optional[Union[str, List[str]]] = None,
    sbuffer: Optional[Union[str, List[str]]] = None,
    normal_angle: Optional[Union[float, str, List[Optional[Union[float, str]]]]] = None,
    machine: Optional[Union[str, "os.PathLike[str]"]] = None,
    repeat: int = 3,
    threads: int = 1,
    client: Any = None,
) -> List[Dict[str, Any]]:
    """``cwisim tradeoff``: a scene drawn over a grid of settings, each measured (what it
    costs the array and the host against its error from the exact image), the Pareto
    front of bus cycles, register bits and RMS error marked. Returns the rows, in the
    grid's order, as dicts with the CSV's fields (and the renderer's ``counters``);
    :func:`frame` makes a pandas DataFrame of them.

    ``scene``: a file or an embedded name, or a list of them — settings × scenes: each
    scene's grid in turn, each row with its ``scene``, each scene's front marked among
    its own rows. The axes default to the command line's: every one-frame renderer,
    ``tessellate`` (4, 8, 16) on a scene with patches, the scene's own shadows, the five
    default ``numeric`` formats, ``sbuffer``'s ``host`` mode, ``nishita`` without the
    normal-angle test. ``sbuffer``: the command line's ``--sbuffer`` (``["host",
    "abuffer"]``: the scanline A-buffer's rows too, their ``aa`` ``"abuffer"``);
    ``normal_angle``: its ``--normal-angle``, degrees and ``None`` (or ``"off"``) for the
    test off (``[None, 20]``). ``threads``: measured on that many threads in this
    process. ``client``: a ``dask.distributed.Client``: each group of settings that
    shares a stream (of every scene) becomes a Dask task, run on the cluster's workers,
    and the rows gathered in the same order — equal to the local sweep's, row for row,
    but for the host times.

    A field that does not apply to a row is ``None``: ``aa`` (a renderer that does not
    read it), ``samples`` (one that does not supersample), ``visibility``, ``shadows``
    (a screen scene), ``tessellate``, ``root_tolerance`` and ``normal_angle`` (also
    ``None`` on a ``nishita`` row without the test). A renderer left out of the
    grid (``nishita`` on a scene without Bézier patches) is a :class:`TradeoffWarning`
    saying why, as the command line's ``skipped nishita: …``.
    """
    many = isinstance(scene, (list, tuple))
    plans = [
        _plan_args(one, size, tessellate, shadows, renderers, numeric, machine, sbuffer, normal_angle)
        for one in (scene if many else [scene])
    ]
    native = [_native.TradeoffPlan(**args) for args in plans]
    for args, plan in zip(plans, native):
        # as the command line says `skipped nishita: …`
        for name, why in plan.skipped():
            where = f" (scene {args['scene']})" if many else ""
            warnings.warn(f"skipped {name}{where}: {why}", TradeoffWarning, stacklevel=2)
    if client is not None:
        from . import sweep  # noqa: PLC0415 (Dask is optional)

        per_scene = sweep.tradeoff_on(client, plans, repeat)
    else:
        per_scene = [_measured_here(plan, repeat, threads) for plan in native]
    rows: List[Dict[str, Any]] = []
    for args, scene_rows in zip(plans, per_scene):
        mark_pareto(scene_rows)
        if many:
            for r in scene_rows:
                r["scene"] = args["scene"]
        rows.extend(scene_rows)
    return rows


def _measured_here(plan: Any, repeat: int, threads: int) -> List[Dict[str, Any]]:
    """The rows of one plan, measured in this process on ``threads`` threads, unmarked."""
    rows: List[Dict[str, Any]] = []
    if threads == 1:
        for g in range(plan.groups()):
            rows.extend(rows_of(plan.measure(g, repeat)))
        return rows
    from concurrent.futures import ThreadPoolExecutor  # noqa: PLC0415

    workers = threads if threads > 0 else (os.cpu_count() or 1)
    with ThreadPoolExecutor(workers) as pool:
        for group in pool.map(lambda g: plan.measure(g, repeat), range(plan.groups())):
            rows.extend(rows_of(group))
    return rows


#: The fields of a tradeoff row that may not apply to its renderer or scene (the CSV's
#: ``-``); ``None`` in Python, as ``samples``, ``tessellate``, ``root_tolerance`` and
#: ``normal_angle`` are.
NOT_APPLICABLE = ("aa", "visibility", "shadows")


def rows_of(text: str) -> List[Dict[str, Any]]:
    """Rows from the native module's JSON: an exact image's PSNR (infinite, which JSON
    cannot say) back to ``inf``; a field that does not apply (the CSV's ``-``) ``None``."""
    rows = json.loads(text)
    for r in rows:
        if r.get("psnr_db") is None:
            r["psnr_db"] = float("inf")
        for k in NOT_APPLICABLE:
            if r.get(k) == "-":
                r[k] = None
    return rows


def mark_pareto(rows: List[Dict[str, Any]]) -> List[Dict[str, Any]]:
    """Marks ``rows["pareto"]`` as ``tradeoff`` does (over bus cycles, register bits and
    RMS error), in place; returns the rows."""
    flags = _native.pareto(
        [(r["busy_cycles"], r["register_bits"], r["rms_error"]) for r in rows]
    )
    for r, f in zip(rows, flags):
        r["pareto"] = f
    return rows


def frame(rows: List[Dict[str, Any]]):
    """Rows (of :func:`tradeoff`) as a pandas DataFrame, the renderer's counters left out
    (pandas: installed by ``crates/python/install.sh``; not needed by the rest of cwisim)."""
    return _pandas().DataFrame([{k: v for k, v in r.items() if k != "counters"} for r in rows])


#: Opcode names by binary code (``Stream.instructions["op"]`` holds the names).
OPCODES: Dict[int, str] = dict(_native.opcodes())


@dataclass
class Stream:
    """An instruction stream: the trace header (``width`` processors, ``lines`` per
    frame, ``channels``) and the instructions as a NumPy structured array with fields
    ``op`` (the opcode's name: ``"Eval2"``), ``x`` (first processor), ``dx`` (count or
    period), ``I``, ``dI``, ``ddI`` (one value per channel; NaN in a slot the opcode
    does not carry) and ``note``: the instruction's provenance, an index into ``notes``
    (``-1``: none) — the renderer's note on where it came from (``row 3 trapezium 4
    (polygon 2): case 8: …``), kept by ``.cwt`` and ``.jsonl``, not by ``.cwb``."""

    width: int
    lines: int
    channels: int
    instructions: np.ndarray
    notes: List[str] = field(default_factory=list)

    def note(self, k: int) -> Optional[str]:
        """Instruction ``k``'s note, if it has one."""
        n = int(self.instructions["note"][k])
        return self.notes[n] if n >= 0 else None

    def write(self, path: Union[str, "os.PathLike[str]"]) -> None:
        """Writes the stream as a trace file, its encoding by the extension (``.cwt``
        annotated text, ``.jsonl``, ``.cwb`` binary); every instruction is checked first
        (one that does not fit raises :class:`UsageError` naming it). All or nothing: the
        file is written beside its place and renamed over it, and a path that is not a
        regular file (a device, a FIFO, a symlink) is refused."""
        path = Path(path)
        ins = self.instructions
        codes = {name: code for code, name in OPCODES.items()}
        try:
            code = np.array([codes[str(op)] for op in ins["op"]], dtype=np.uint8)
        except KeyError as e:
            raise UsageError(f"no opcode is called {e}") from None
        values = np.stack([ins["I"], ins["dI"], ins["ddI"]], axis=1).reshape(
            len(ins), 3, self.channels
        )
        data = _native.encode_trace(
            self.width,
            self.lines,
            self.channels,
            code,
            np.ascontiguousarray(ins["x"], dtype=np.uint32),
            np.ascontiguousarray(ins["dx"], dtype=np.uint32),
            np.ascontiguousarray(values, dtype=np.float64),
            np.ascontiguousarray(ins["note"], dtype=np.int32),
            list(self.notes),
            path.suffix.lstrip("."),
        )
        _write_whole(path, data)

    def __len__(self) -> int:
        return len(self.instructions)


def _stream_of(out: Mapping[str, Any]) -> Stream:
    ch = out["channels"]
    n = len(out["code"])
    names = np.array([OPCODES.get(c, "?") for c in range(256)], dtype="U8")
    ins = np.empty(
        n,
        dtype=[
            ("op", "U8"),
            ("x", "u4"),
            ("dx", "u4"),
            ("I", "f8", (ch,)),
            ("dI", "f8", (ch,)),
            ("ddI", "f8", (ch,)),
            ("note", "i4"),
        ],
    )
    ins["op"] = names[out["code"]]
    ins["x"] = out["x"]
    ins["dx"] = out["dx"]
    values = out["values"]
    ins["I"], ins["dI"], ins["ddI"] = values[:, 0, :], values[:, 1, :], values[:, 2, :]
    ins["note"] = out["note"]
    return Stream(out["width"], out["lines"], ch, ins, list(out["notes"]))


def _write_whole(path: Path, data: bytes) -> None:
    """``data`` to ``path``, all or nothing; only a regular file (or none) is replaced."""
    if path.is_symlink() or (path.exists() and not path.is_file()):
        raise UsageError(f"{path}: not a regular file; it is not replaced")
    temp = path.with_name(f".{path.name}.{os.getpid()}.partial")
    try:
        temp.write_bytes(data)
        os.replace(temp, path)
    finally:
        if temp.exists():
            temp.unlink()


def emit(
    scene: SceneLike = None,
    renderer: str = "vanrij",
    *,
    threads: int = 1,
    **settings: Any,
) -> Stream:
    """The instruction stream ``renderer`` sends for ``scene`` (what ``cwisim emit``
    writes), settings as for :func:`render`; ``.write(path)`` saves it as a trace."""
    given = [(k, _spelled(k, v)) for k, v in settings.items() if v is not None]
    return _stream_of(
        _native.emit_stream(**_where(scene), renderer=renderer, settings=_given(settings), threads=threads)
    )


def read_trace(path: Union[str, "os.PathLike[str]"]) -> Stream:
    """A trace file (``.cwt``, ``.jsonl``, ``.cwb``) as a :class:`Stream`. A trace that
    cannot be read raises :class:`SceneError` with the file and the line or byte offset."""
    return _stream_of(_native.read_trace(os.fspath(path)))


def replay(
    trace: Union[str, "os.PathLike[str]", Stream],
    *,
    numeric: str = "f64",
    timing: str = "fast",
    machine: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Render:
    """Replays a trace through the array (``cwisim run``): a trace file, or a
    :class:`Stream` (written to a temporary ``.cwb`` first). Returns a :class:`Render`
    (its ``renderer`` is ``"-"``, it has no counters)."""
    if isinstance(trace, Stream):
        with _written(trace) as path:
            return replay(path, numeric=numeric, timing=timing, machine=machine)
    out = _native.replay(
        os.fspath(trace),
        numeric=numeric,
        timing=timing,
        machine=_path(machine),
    )
    out["scene"] = Path(os.fspath(trace)).stem
    return _render_of(out)


def fit(
    scene: SceneLike = None,
    renderer: str = "vanrij",
    *,
    max_error: float = 1 / 512,
    overflow: str = "saturate",
    machine: Optional[Union[str, "os.PathLike[str]"]] = None,
    threads: int = 0,
    **settings: Any,
) -> Dict[str, Any]:
    """``cwisim fit``: the narrowest fixed-point registers with which the renderer's
    stream for ``scene`` (a file or an embedded name) stays within ``max_error`` of the
    f64 array — model only what the scene requires. Settings as for :func:`render`.
    Returns ``numeric`` (the format, as ``render(numeric=…)`` takes it), ``error``,
    ``exact_error``, ``f64_error``, ``registers`` (name → ``(int_bits, frac_bits, max error
    with one fraction bit fewer)``), ``bits`` (in all), ``replays``, ``instructions``."""
    return dict(
        _native.fit(
            scene=_named(scene, "fit"),
            renderer=renderer,
            settings=_given(settings),
            max_error=float(max_error),
            overflow=overflow,
            machine=_path(machine),
            threads=threads,
        )
    )


def refine(
    scene: SceneLike = None,
    *,
    phases: str = "flat,gouraud,phong,aa",
    machine: Optional[Union[str, "os.PathLike[str]"]] = None,
    threads: int = 1,
    **settings: Any,
) -> Dict[str, Any]:
    """``cwisim refine``: Bergman et al.'s adaptive refinement of a world scene (a file or
    an embedded name), each phase a complete frame, beside the naive sequence (every
    phase in full). ``phases`` as ``--phases`` takes them; settings: ``gouraud_threshold``,
    ``phong_angle``, ``aa_threshold``, ``size``, ``tessellate``, ``shade_tolerance``,
    ``shadows``. Returns ``phases`` and ``naive`` (a dict per phase: ``pixels``,
    ``instructions``, ``regenerated``, ``busy_cycles``, ``cumulative_cycles``,
    ``worst_line_cycles``, ``late_lines``, ``rms``, ``psnr_db``, ``display_list_bytes``),
    ``frames`` (frames × lines × width × channels), ``busy_per_line`` (frames × lines),
    ``counters``, ``polygons``, ``highlight``, ``line_period``, ``frame_buffer_bytes``."""
    return dict(
        _native.refine(
            scene=_named(scene, "refine"),
            phases=phases,
            settings=_given(settings),
            machine=_path(machine),
            threads=threads,
        )
    )


def history(
    trace: Union[str, "os.PathLike[str]", Stream],
    x: int,
    line: int,
    *,
    numeric: str = "f64",
    machine: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> List[Dict[str, Any]]:
    """``cwisim history``: every visit of a token to processor ``x`` on scanline ``line``
    of a trace (a file, or a :class:`Stream`), in order, on the cycle-stepped engine: a
    dict per visit with ``cycle``, ``index`` (the instruction's), ``instruction`` (its
    text), ``op``, ``addressed``, ``before`` and ``after`` (``acc``, ``I``, ``dI``,
    ``ddI``, ``has``, ``locked``, ``masked``, ``negative_enabled``), ``note`` (``"passes
    through"``, ``"suppressed: …"`` or ``None``) and ``provenance`` (the trace's note on
    the instruction, when it has one)."""
    if isinstance(trace, Stream):
        with _written(trace, "jsonl") as path:
            return history(path, x, line, numeric=numeric, machine=machine)
    return list(
        _native.history(
            os.fspath(trace),
            x,
            line,
            numeric=numeric,
            machine=_path(machine),
        )
    )


@dataclass
class Waveform:
    """A scanline's per-cycle waveform (``cwisim vcd``'s contents): from ``start``, the
    cycle the bus starts issuing the scanline, to ``end``, the cycle it leaves the array.
    ``signals``: ``"scope.name"`` (``"bus.opcode"``, ``"p5.acc"``, ``"p5.I_c1"`` for a
    channel of several) → ``(cycles, values)``, the value at ``start`` and at each cycle
    it changes (bits 0 or 1, words their value or NaN when nothing drives them)."""

    start: int
    end: int
    signals: Dict[str, Tuple[np.ndarray, np.ndarray]]

    def sampled(self, name: str) -> Tuple[np.ndarray, np.ndarray]:
        """Signal ``name`` at every cycle from ``start`` to ``end``: ``(cycles, values)``,
        for plotting as a step function."""
        cycles, values = self.signals[name]
        every = np.arange(self.start, self.end + 1, dtype=np.uint64)
        return every, values[np.searchsorted(cycles, every, side="right") - 1]


def waveform(
    trace: Union[str, "os.PathLike[str]", Stream],
    line: int,
    x: Union[int, Tuple[int, int], range, None] = None,
    *,
    numeric: str = "f64",
    machine: Optional[Union[str, "os.PathLike[str]"]] = None,
) -> Waveform:
    """``cwisim vcd``: scanline ``line`` of a trace (a file or a :class:`Stream`) cycle by
    cycle on the stepped engine — the bus and the processors ``x``: one (``5``), a pair
    ``(first, last)`` (both included), a ``range``, or ``None``: the whole array (at most
    512 processors, as the command line allows)."""
    if isinstance(trace, Stream):
        with _written(trace) as path:
            return waveform(path, line, x, numeric=numeric, machine=machine)
    if x is None:
        width = _native.trace_header(os.fspath(trace))[0]
        if width > 512:
            raise UsageError(f"the array is {width} processors wide: choose a window of at most 512 (x=…)")
        first, last = 0, width - 1
    elif isinstance(x, range):
        if x.step != 1 or len(x) == 0:
            raise UsageError("x: a range of consecutive processors, not empty")
        first, last = x.start, x.stop - 1
    elif isinstance(x, tuple):
        first, last = x
    else:
        first = last = int(x)
    out = _native.waveform(
        os.fspath(trace), line, first, last, numeric=numeric, machine=_path(machine)
    )
    return Waveform(out["start"], out["end"], dict(out["signals"]))
