//! # cwisim-python — the native module of the `cwisim` Python package
//!
//! `cwisim._native`, built by maturin over PyO3 against the stable ABI (one wheel for
//! every CPython from 3.9). Like the command line, it converts and dispatches only: the
//! scene is read, the settings checked and the renderer built by
//! [`cwisim_render::draw::draw`], the frame rendered by [`cwisim_render::render`], and
//! what comes back is handed to Python as NumPy arrays (the image without a copy) and
//! plain dictionaries. The Python layer (`python/cwisim/__init__.py`) wraps these in the
//! documented API (docs/PYTHON.md); the settings keep the command line's names
//! (`shade_tolerance` for `--shade-tolerance`) and spellings.
//!
//! Errors are Python exceptions carrying the command line's located message:
//! `SceneError` (a scene that cannot be read: file, line or JSON path, what was
//! expected), `UsageError` (unknown names, settings that do not go together or exceed a
//! limit), both `CwisimError`s; a fault of cwisim's own is a plain `CwisimError`. They
//! are the `cwisim` module's (`cwisim.UsageError`, found there by pickle), and a
//! `UsageError` names the command line's flags as keyword arguments (`samples=`,
//! [`keyword_spelling`]). `Render.summary` is the library's
//! [`cwisim_render::summary::render_rows`], the rows `cwisim render` prints. The
//! render runs without the GIL, and stops after the scanline during which Ctrl-C came
//! (`KeyboardInterrupt`).

use cwisim_isa::note::NoteTaker;
use cwisim_isa::{
    Encoding, FileReader, Instruction, NoteTable, Opcode, TraceError, TraceHeader, TraceRead,
};
use cwisim_render::draw::{draw, SceneInput};
use cwisim_render::refine::parse_phases;
use cwisim_render::settings::{keyword_spelling, Setting};
use cwisim_render::{
    registry, render as render_frames, ArrayConfig, RenderError, Rendered, Settings, Taps,
};
use cwisim_study::error::StudyError;
use cwisim_study::fit::{fit_scene, q, REGISTERS};
use cwisim_study::history::pixel_history_with_progress;
use cwisim_study::refine::{run_refine, PhaseRow, RefineSetup};
use cwisim_study::tradeoff;
use cwisim_study::vcd::record_scanline_with_progress;
use cwisim_xproc::numeric::Overflow;
use cwisim_xproc::{
    Image, ImageSink, LineStats, Machine, Numeric, ProcessorState, ReplayError, Timing,
};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray3};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyKeyboardInterrupt};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

create_exception!(
    cwisim,
    CwisimError,
    PyException,
    "Anything cwisim refuses or fails at; the message says what and where."
);
create_exception!(
    cwisim,
    SceneError,
    CwisimError,
    "A scene that cannot be read: the message locates it (the file, the line or JSON path) and says what was expected."
);
create_exception!(
    cwisim,
    UsageError,
    CwisimError,
    "An unknown name, settings that do not go together, or a size over a limit: the command line's exit 2."
);

/// A `UsageError` of `message`, its command-line flags spoken as keyword arguments
/// (`--samples` → `samples=`, [`keyword_spelling`]).
fn usage_error(message: impl AsRef<str>) -> PyErr {
    UsageError::new_err(keyword_spelling(message.as_ref()))
}

/// A message of the command line's with its flags spoken as keyword arguments, as every
/// `UsageError` says them (`--samples` → `samples=`).
#[pyfunction(name = "keyword_spelling")]
fn keyword_spelling_py(message: &str) -> String {
    keyword_spelling(message)
}

/// The Python exception for a render error: the same message as the command line's.
fn to_py(e: RenderError) -> PyErr {
    let message = e.to_string();
    match e {
        RenderError::Scene(_) => SceneError::new_err(message),
        RenderError::Usage(_)
        | RenderError::UnknownRenderer { .. }
        | RenderError::Machine(_)
        | RenderError::ImageLimit(_)
        | RenderError::Overflow { .. } => usage_error(message),
        RenderError::Cancelled { .. } => PyKeyboardInterrupt::new_err(message),
        RenderError::Renderer { .. } | RenderError::Array(_) => CwisimError::new_err(message),
    }
}

/// Runs `work` without the GIL on a thread of its own while this thread asks Python for
/// signals every 20 ms: on Ctrl-C, `work`'s cancel flag is set (it stops at its next
/// check) and `KeyboardInterrupt` is raised once it has returned, whatever it returned.
fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    let cancel = AtomicBool::new(false);
    let (out, interrupted) = py.detach(|| {
        std::thread::scope(|scope| {
            let handle = scope.spawn(|| work(&cancel));
            let mut interrupted = false;
            while !handle.is_finished() {
                std::thread::sleep(std::time::Duration::from_millis(20));
                if !interrupted && Python::attach(|py| py.check_signals().is_err()) {
                    interrupted = true;
                    cancel.store(true, Ordering::Relaxed);
                }
            }
            (handle.join(), interrupted)
        })
    });
    if interrupted {
        return Err(PyKeyboardInterrupt::new_err("interrupted"));
    }
    out.map_err(|_| CwisimError::new_err("cwisim failed: its worker thread panicked"))
}

/// The embedded scenes: `(name, one line about it)`, in `cwisim scenes`' order.
#[pyfunction]
fn scenes() -> Vec<(&'static str, &'static str)> {
    cwisim_world::embedded::EMBEDDED
        .iter()
        .map(|e| (e.name, e.about))
        .collect()
}

/// The JSON text of the embedded scene `name` (what `cwisim scenes NAME` prints).
#[pyfunction]
fn scene_text(name: &str) -> PyResult<&'static str> {
    cwisim_world::embedded::embedded(name)
        .map(|e| e.text)
        .ok_or_else(|| {
            let names: Vec<&str> = cwisim_world::embedded::EMBEDDED
                .iter()
                .map(|e| e.name)
                .collect();
            usage_error(format!(
                "no embedded scene `{name}` (embedded: {})",
                names.join(", ")
            ))
        })
}

/// The registered renderers: `(name, about, the settings it reads)`, settings by their
/// Python names.
#[pyfunction]
fn renderers() -> Vec<(&'static str, &'static str, Vec<String>)> {
    registry::REGISTRY
        .iter()
        .map(|e| {
            let uses = e.uses.iter().map(|s| python_name(*s)).collect();
            (e.name, e.about, uses)
        })
        .collect()
}

/// Every drawing setting's Python name, in the command line's order.
#[pyfunction]
fn setting_names() -> Vec<String> {
    Setting::ALL.into_iter().map(python_name).collect()
}

fn python_name(s: Setting) -> String {
    s.name().replace('-', "_")
}

/// The settings `given` (Python name → the command line's spelling of the value) over
/// the defaults, with `threads`; the settings given, for the renderer to check.
fn settings_of(given: &[(String, String)], threads: usize) -> PyResult<(Settings, Vec<Setting>)> {
    let mut settings = Settings {
        threads,
        ..Settings::default()
    };
    let mut named = Vec::new();
    for (name, value) in given {
        let setting = Setting::of_name(name).ok_or_else(|| {
            usage_error(format!(
                "unknown setting `{name}`; known: {}",
                setting_names().join(", ")
            ))
        })?;
        setting
            .set(&mut settings, value)
            .map_err(|e| usage_error(format!("{name}: {e}")))?;
        named.push(setting);
    }
    Ok((settings, named))
}

/// The per-scanline records as named columns.
fn line_columns<'py>(py: Python<'py>, lines: &[LineStats]) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let column = |f: &dyn Fn(&LineStats) -> u64| -> Vec<u64> { lines.iter().map(f).collect() };
    let columns: [(&str, Vec<u64>); 13] = [
        ("line", column(&|l| l.line)),
        ("frame", column(&|l| l.frame)),
        ("row", column(&|l| l.row)),
        ("instructions", column(&|l| l.instructions)),
        ("processor_updates", column(&|l| l.processor_updates)),
        ("dropped_negative", column(&|l| l.dropped_negative)),
        ("suppressed", column(&|l| l.suppressed)),
        ("overflows", column(&|l| l.overflows)),
        ("busy_cycles", column(&|l| l.busy_cycles)),
        ("stall_cycles", column(&|l| l.stall_cycles)),
        ("first_issue", column(&|l| l.first_issue)),
        ("ready", column(&|l| l.ready)),
        ("deadline", column(&|l| l.deadline)),
    ];
    for (name, values) in columns {
        out.set_item(name, PyArray1::from_vec(py, values))?;
    }
    let slack: Vec<i64> = lines.iter().map(|l| l.slack).collect();
    out.set_item("slack", PyArray1::from_vec(py, slack))?;
    let late: Vec<bool> = lines.iter().map(|l| l.slack < 0).collect();
    out.set_item("late", PyArray1::from_vec(py, late))?;
    for op in cwisim_isa::Opcode::ALL {
        let counts: Vec<u64> = lines.iter().map(|l| l.opcodes.get(*op)).collect();
        out.set_item(op.name(), PyArray1::from_vec(py, counts))?;
    }
    Ok(out)
}

/// What a run of the array gives, for Python: `image` (scanlines × width × channels,
/// handed to NumPy without a copy), `totals` and `machine` (JSON text), `lines` (the
/// per-scanline columns), `width`, `channels`, `line_period`, `numeric`.
fn run_dict<'py>(
    py: Python<'py>,
    image: Image,
    stats: &cwisim_xproc::RunStats,
    array: &ArrayConfig,
    numeric: &Numeric,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let shape = [image.lines, image.width, image.channels];
    out.set_item("width", image.width)?;
    out.set_item("channels", image.channels)?;
    out.set_item("image", PyArray1::from_vec(py, image.data).reshape(shape)?)?;
    let json = |v: serde_json::Result<String>| v.map_err(|e| CwisimError::new_err(e.to_string()));
    out.set_item("totals", json(serde_json::to_string(&stats.totals))?)?;
    out.set_item("machine", json(serde_json::to_string(&array.machine))?)?;
    out.set_item("lines", line_columns(py, &stats.lines)?)?;
    out.set_item("line_period", stats.line_period)?;
    out.set_item("numeric", numeric.to_string())?;
    Ok(out)
}

/// The array of `numeric` (`f64`, `f32`, `fixed:…`), `timing` (`fast`, `stepped`) and
/// the machine model in the file `machine` (`None`: the default machine).
fn array_config(numeric: &str, timing: &str, machine: Option<&str>) -> PyResult<ArrayConfig> {
    let numeric: Numeric = numeric
        .parse()
        .map_err(|e| usage_error(format!("numeric: {e}")))?;
    let timing = match timing {
        "fast" => Timing::Fast,
        "stepped" => Timing::Stepped,
        other => {
            return Err(usage_error(format!(
                "timing: unknown timing `{other}`; expected fast or stepped"
            )))
        }
    };
    let machine = match machine {
        Some(path) => Machine::from_file(Path::new(path)).map_err(|e| to_py(e.into()))?,
        None => Machine::default(),
    };
    Ok(ArrayConfig {
        machine,
        numeric,
        timing,
    })
}

/// A stream as columns: `width`, `lines`, `channels` (the header), `code` (each
/// instruction's opcode, its binary code), `x`, `dx`, and `values` (instructions × 3 ×
/// channels: `I`, `dI`, `ddI`, NaN in a slot the opcode does not carry), and its notes
/// (the provenance a renderer or a `.cwt` gives): `notes` each text once, `note` each
/// instruction's place in it (-1: none).
fn stream_dict<'py>(
    py: Python<'py>,
    header: &TraceHeader,
    stream: &[Instruction],
    notes: &NoteTable,
) -> PyResult<Bound<'py, PyDict>> {
    let ch = usize::from(header.channels);
    let out = PyDict::new(py);
    out.set_item("width", header.width)?;
    out.set_item("lines", header.lines)?;
    out.set_item("channels", ch)?;
    let code: Vec<u8> = stream.iter().map(|i| i.op.code()).collect();
    let x: Vec<u32> = stream.iter().map(|i| i.x).collect();
    let dx: Vec<u32> = stream.iter().map(|i| i.dx).collect();
    let mut values = vec![f64::NAN; stream.len() * 3 * ch];
    for (k, i) in stream.iter().enumerate() {
        for slot in 0..3 {
            let v = i.value(slot);
            if !v.is_empty() {
                values[(k * 3 + slot) * ch..][..ch].copy_from_slice(v);
            }
        }
    }
    // each note once, in the order first met; each instruction its note's place (-1: none)
    let mut texts: Vec<String> = Vec::new();
    let mut note = vec![-1i32; stream.len()];
    for (range, n) in notes.runs() {
        let at = match texts.iter().position(|t| t == n.text) {
            Some(k) => k,
            None => {
                texts.push(n.text.to_string());
                texts.len() - 1
            }
        };
        for k in range {
            if let Some(slot) = usize::try_from(k).ok().and_then(|k| note.get_mut(k)) {
                *slot = i32::try_from(at).unwrap_or(i32::MAX);
            }
        }
    }
    out.set_item("note", PyArray1::from_vec(py, note))?;
    out.set_item("notes", texts)?;
    out.set_item("code", PyArray1::from_vec(py, code))?;
    out.set_item("x", PyArray1::from_vec(py, x))?;
    out.set_item("dx", PyArray1::from_vec(py, dx))?;
    out.set_item(
        "values",
        PyArray1::from_vec(py, values).reshape([stream.len(), 3, ch])?,
    )?;
    Ok(out)
}

/// The opcodes: `(binary code, name)`, in code order.
#[pyfunction]
fn opcodes() -> Vec<(u8, &'static str)> {
    Opcode::ALL.iter().map(|o| (o.code(), o.name())).collect()
}

/// The instruction stream a renderer sends for a scene (as [`render`] draws it), as
/// columns ([`stream_dict`]). A renderer that draws each frame from the previous one's
/// output has no stream without the array, and is refused.
#[pyfunction]
#[pyo3(signature = (scene=None, scene_json=None, name="scene", renderer="vanrij", settings=Vec::new(), threads=1))]
fn emit_stream<'py>(
    py: Python<'py>,
    scene: Option<&str>,
    scene_json: Option<&str>,
    name: &str,
    renderer: &str,
    settings: Vec<(String, String)>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    cwisim_scene::budget::check_threads(threads).map_err(usage_error)?;
    let (settings, given) = settings_of(&settings, threads)?;
    let input = match (scene, scene_json) {
        (_, Some(text)) => SceneInput::Text { name, text },
        (path, None) => SceneInput::Named(path.map(Path::new)),
    };
    let (header, stream, notes) = py
        .detach(|| {
            let drawn = draw(renderer, input, &given, &settings)?;
            let mut taker = NoteTaker::new(Vec::<Instruction>::new());
            cwisim_render::emit(&*drawn.renderer, &mut taker)?;
            let (stream, notes) = taker.into_parts();
            Ok::<_, RenderError>((drawn.renderer.header(), stream, notes))
        })
        .map_err(to_py)?;
    stream_dict(py, &header, &stream, &notes)
}

/// The trace file `path` (`.cwt`, `.jsonl` or `.cwb`), read and checked, as columns
/// ([`stream_dict`]); a trace that cannot be read raises `SceneError` with its location.
#[pyfunction]
fn read_trace<'py>(py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyDict>> {
    let (header, stream, notes) = py
        .detach(|| {
            let mut reader = FileReader::open(Path::new(path))?;
            let mut stream = Vec::new();
            let mut notes = NoteTable::new();
            while let Some(i) = reader.next_instruction()? {
                if let Some(n) = reader.note() {
                    notes.record(stream.len() as u64, n);
                }
                stream.push(i);
            }
            Ok::<_, TraceError>((*reader.header(), stream, notes))
        })
        .map_err(|e| SceneError::new_err(e.to_string()))?;
    stream_dict(py, &header, &stream, &notes)
}

/// The header of the trace file `path`: `(width, lines, channels)`, read without the
/// instructions.
#[pyfunction]
fn trace_header(path: &str) -> PyResult<(u32, u32, u8)> {
    let reader =
        FileReader::open(Path::new(path)).map_err(|e| SceneError::new_err(e.to_string()))?;
    let h = reader.header();
    Ok((h.width, h.lines, h.channels))
}

/// Columns ([`stream_dict`]'s) encoded as a trace of `encoding` (`cwt`, `jsonl`, `cwb`),
/// every instruction checked against the header first: one that does not fit raises
/// `UsageError` naming it (its index, what is wrong).
#[pyfunction]
#[allow(clippy::too_many_arguments)] // the stream's columns
fn encode_trace<'py>(
    py: Python<'py>,
    width: u32,
    lines: u32,
    channels: u8,
    code: PyReadonlyArray1<'py, u8>,
    x: PyReadonlyArray1<'py, u32>,
    dx: PyReadonlyArray1<'py, u32>,
    values: PyReadonlyArray3<'py, f64>,
    note: PyReadonlyArray1<'py, i32>,
    notes: Vec<String>,
    encoding: &str,
) -> PyResult<Bound<'py, PyBytes>> {
    let header = TraceHeader::new(width, lines, channels)
        .map_err(|e| usage_error(format!("header: {e}")))?;
    let encoding = Encoding::ALL
        .iter()
        .find(|(_, ext)| *ext == encoding)
        .map(|(e, _)| *e)
        .ok_or_else(|| {
            usage_error(format!(
                "unknown trace encoding `{encoding}`; expected cwt, jsonl or cwb"
            ))
        })?;
    let (code, x, dx, values, note) = (
        code.as_slice()?,
        x.as_slice()?,
        dx.as_slice()?,
        values.as_slice()?,
        note.as_slice()?,
    );
    let ch = usize::from(channels);
    let n = code.len();
    if x.len() != n || dx.len() != n || note.len() != n || values.len() != n * 3 * ch {
        return Err(usage_error(format!(
            "the columns disagree: {n} opcodes, {} x, {} dx, {} values (expected {} = {n} × 3 × {ch})",
            x.len(),
            dx.len(),
            values.len(),
            n * 3 * ch
        )));
    }
    let mut stream = Vec::with_capacity(n);
    for k in 0..n {
        let op = Opcode::from_code(code[k]).ok_or_else(|| {
            usage_error(format!(
                "instruction {k}: no opcode has the code {}",
                code[k]
            ))
        })?;
        let i =
            Instruction::from_operands(op, x[k], dx[k], dx[k], &values[k * 3 * ch..][..3 * ch], ch);
        i.check(&header).map_err(|e| {
            usage_error(format!("instruction {k} ({}): {}", op.name(), e.message()))
        })?;
        stream.push(i);
    }
    let mut bytes = Vec::new();
    {
        let mut w = encoding
            .writer(&mut bytes, &header)
            .map_err(|e| CwisimError::new_err(e.to_string()))?;
        let fault = |e: std::io::Error| CwisimError::new_err(e.to_string());
        for (k, i) in stream.iter().enumerate() {
            // a note is attached to the first instruction it covers: where it changes,
            // or after a Refresh (notes never cover two scanlines)
            let fresh = k == 0 || note[k] != note[k - 1] || stream[k - 1].op == Opcode::Refresh;
            let text = usize::try_from(note[k]).ok().and_then(|n| notes.get(n));
            if let (true, Some(text)) = (fresh, text) {
                w.comment(text).map_err(fault)?;
            }
            w.write(i).map_err(fault)?;
        }
        w.finish()
            .map_err(|e| CwisimError::new_err(e.to_string()))?;
    }
    Ok(PyBytes::new(py, &bytes))
}

/// Why a replay was refused, made without the GIL: the trace's fault (`SceneError`) or
/// the settings' (`UsageError`).
enum Refused {
    Input(String),
    Usage(String),
}

/// Replays the trace file `path` through the array, as `cwisim run` does: the run's
/// [`run_dict`], and `frames` and `height` (scanlines per frame). A trace that cannot be
/// read raises `SceneError` with its location.
#[pyfunction]
#[pyo3(signature = (path, numeric="f64", timing="fast", machine=None))]
fn replay<'py>(
    py: Python<'py>,
    path: &str,
    numeric: &str,
    timing: &str,
    machine: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let array = array_config(numeric, timing, machine)?;
    let budget = cwisim_scene::budget::Budget::current();
    let (header, image, stats) = py
        .detach(|| {
            let mut reader =
                FileReader::open(Path::new(path)).map_err(|e| Refused::Input(e.to_string()))?;
            let header = *reader.header();
            let mut sink = ImageSink::new(
                header.width as usize,
                usize::from(header.channels),
                budget.memory_bytes,
            );
            let stats = cwisim_xproc::replay_numeric(
                &mut reader,
                &array.machine,
                array.timing,
                &array.numeric,
                &mut sink,
                &mut |_| {},
            )
            .map_err(|e| match e {
                ReplayError::Trace(e) => Refused::Input(e.to_string()),
                other => Refused::Usage(other.to_string()),
            })?;
            let image = sink.finish().map_err(|e| Refused::Usage(e.to_string()))?;
            Ok::<_, Refused>((header, image, stats))
        })
        .map_err(|e| match e {
            Refused::Input(m) => SceneError::new_err(m),
            Refused::Usage(m) => usage_error(m),
        })?;
    let out = run_dict(py, image, &stats, &array, &array.numeric)?;
    out.set_item("height", header.lines)?;
    out.set_item("frames", stats.totals.frames)?;
    Ok(out)
}

/// What [`render`] makes without the GIL: everything but the Python objects.
struct Done {
    image: Image,
    rendered: Rendered,
    summary: Vec<(String, String)>,
    renderer: &'static str,
    phrase: String,
    scene: String,
    kind: &'static str,
    height: u32,
    frames: u32,
}

/// The scene drawn by the renderer (as the command line's `render` does) and rendered
/// into the array `array`, its image collected; the image's memory checked against the
/// budget before it is allocated.
fn drawn_and_rendered(
    renderer: &str,
    input: SceneInput<'_>,
    given: &[Setting],
    settings: &Settings,
    array: &ArrayConfig,
    progress: Option<&Py<PyAny>>,
) -> Result<Done, RenderError> {
    let drawn = draw(renderer, input, given, settings)?;
    let r = &*drawn.renderer;
    let h = r.header();
    let frames_lines = u64::from(h.lines) * u64::from(r.frames());
    let bytes = frames_lines
        .saturating_mul(u64::from(h.width))
        .saturating_mul(h.channel_count() as u64)
        .saturating_mul(8);
    cwisim_scene::budget::Budget::current()
        .check_memory(
            &format!(
                "the image of {frames_lines} scanline(s) of {} × {} value(s)",
                h.width,
                h.channel_count()
            ),
            bytes,
        )
        .map_err(|e| RenderError::Usage(e.to_string()))?;
    let mut sink = ImageSink::new(h.width as usize, h.channel_count(), bytes.max(1));
    // after each scanline: the progress callback told (scanlines done, of all), and
    // Python's signal handlers run (Ctrl-C); a callback that raises stops the render too
    let failed = std::cell::Cell::new(false);
    let mut told = |lines: u64| {
        if let Some(callback) = progress {
            Python::attach(|py| {
                if let Err(e) = callback.call1(py, (lines, frames_lines)) {
                    e.restore(py);
                    failed.set(true);
                }
            });
        }
    };
    let interrupted = || failed.get() || Python::attach(|py| py.check_signals().is_err());
    let taps = Taps {
        cancel: Some(&interrupted),
        progress: Some(&mut told),
        ..Taps::default()
    };
    let rendered = render_frames(r, array, settings.threads, &mut sink, taps)?;
    Ok(Done {
        image: sink.finish()?,
        summary: cwisim_render::summary::render_rows(&drawn, &rendered, &array.numeric),
        rendered,
        renderer: r.name(),
        phrase: r.settings_phrase(),
        scene: drawn.source.name(),
        kind: drawn.kind,
        height: h.lines,
        frames: r.frames(),
    })
}

/// Renders a scene: `scene` a file or an embedded name (`None`: the default scene), or
/// `scene_json` the scene itself as JSON text (named `name`); `settings` the drawing
/// settings by Python name, each value spelled as on the command line. Returns a dict:
/// `image` (scanlines × width × channels, float64), `counters` (the renderer's),
/// `totals` and `machine` (JSON text), `lines` (per-scanline columns), `summary` (the
/// renderer's summary rows), `renderer`, `phrase` (the settings in words), `scene`,
/// `kind`, `width`, `height`, `channels`, `frames`, `line_period`.
#[pyfunction]
#[pyo3(signature = (scene=None, scene_json=None, name="scene", renderer="vanrij", settings=Vec::new(), numeric="f64", timing="fast", machine=None, threads=1, progress=None))]
#[allow(clippy::too_many_arguments)]
fn render<'py>(
    py: Python<'py>,
    scene: Option<&str>,
    scene_json: Option<&str>,
    name: &str,
    renderer: &str,
    settings: Vec<(String, String)>,
    numeric: &str,
    timing: &str,
    machine: Option<&str>,
    threads: usize,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    cwisim_scene::budget::check_threads(threads).map_err(usage_error)?;
    let (settings, given) = settings_of(&settings, threads)?;
    let array = array_config(numeric, timing, machine)?;
    let input = match (scene, scene_json) {
        (_, Some(text)) => SceneInput::Text { name, text },
        (path, None) => SceneInput::Named(path.map(Path::new)),
    };
    let done = py
        .detach(|| {
            drawn_and_rendered(
                renderer,
                input,
                &given,
                &settings,
                &array,
                progress.as_ref(),
            )
        })
        .map_err(|e| match (&e, PyErr::take(py)) {
            // stopped by the progress callback's own exception: that one
            (RenderError::Cancelled { .. }, Some(raised)) => raised,
            _ => to_py(e),
        })?;
    let out = run_dict(py, done.image, &done.rendered.stats, &array, &array.numeric)?;
    let counters = PyDict::new(py);
    for (k, v) in done.rendered.counters.iter() {
        counters.set_item(k, v)?;
    }
    out.set_item("counters", counters)?;
    out.set_item("summary", PyList::new(py, done.summary)?)?;
    out.set_item("renderer", done.renderer)?;
    out.set_item("phrase", done.phrase)?;
    out.set_item("scene", done.scene)?;
    out.set_item("kind", done.kind)?;
    out.set_item("height", done.height)?;
    out.set_item("frames", done.frames)?;
    Ok(out)
}

/// The Python exception for a study error.
fn study_to_py(e: StudyError) -> PyErr {
    match e {
        StudyError::Render(e) => to_py(e),
        StudyError::Trace(e) => SceneError::new_err(e.to_string()),
        StudyError::Machine(_) | StudyError::ImageLimit(_) | StudyError::Usage(_) => {
            usage_error(e.to_string())
        }
        StudyError::Array(_) | StudyError::Plot(_) => CwisimError::new_err(e.to_string()),
        StudyError::Cancelled => PyKeyboardInterrupt::new_err("interrupted"),
    }
}

/// The array's numeric formats `tradeoff` tries by default.
#[pyfunction]
fn default_formats() -> Vec<&'static str> {
    tradeoff::DEFAULT_FORMATS.to_vec()
}

/// The tessellations `tradeoff` tries by default on a scene with Bézier patches.
#[pyfunction]
fn default_tessellations() -> Vec<u32> {
    tradeoff::DEFAULT_TESSELLATIONS.to_vec()
}

/// A `tradeoff` sweep planned ([`tradeoff::Plan`]): its groups of settings, each measured
/// alone (`measure`), so that each can be a task of its own (a Dask task). The rows of
/// every group in order, marked by [`pareto`], are the sweep's.
#[pyclass(frozen, module = "cwisim._native")]
struct TradeoffPlan {
    plan: tradeoff::Plan,
    machine: Machine,
}

#[pymethods]
impl TradeoffPlan {
    /// The plan of `scene` (a file or an embedded name; `None`: the default) over the
    /// axes, as `cwisim tradeoff` takes them.
    #[new]
    #[pyo3(signature = (scene=None, size=None, tessellate=Vec::new(), shadows=Vec::new(), renderers=Vec::new(), numeric=Vec::new(), sbuffer=Vec::new(), normal_angle=Vec::new(), machine=None))]
    #[allow(clippy::too_many_arguments)] // Python's keywords: the command line's flags
    fn new(
        py: Python<'_>,
        scene: Option<&str>,
        size: Option<&str>,
        tessellate: Vec<u32>,
        shadows: Vec<bool>,
        renderers: Vec<String>,
        numeric: Vec<String>,
        sbuffer: Vec<String>,
        normal_angle: Vec<Option<f64>>,
        machine: Option<&str>,
    ) -> PyResult<TradeoffPlan> {
        let size = size
            .map(|s| s.parse::<cwisim_render::Size>())
            .transpose()
            .map_err(|e| usage_error(format!("size: {e}")))?;
        let formats = numeric
            .iter()
            .map(|f| f.parse::<Numeric>())
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| usage_error(format!("numeric: {e}")))?;
        let sbuffer = sbuffer
            .iter()
            .map(|m| m.parse::<cwisim_render::settings::SbufferMode>())
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| usage_error(format!("sbuffer: {e}")))?;
        let machine = match machine {
            Some(path) => Machine::from_file(Path::new(path)).map_err(|e| to_py(e.into()))?,
            None => Machine::default(),
        };
        let request = tradeoff::Request {
            size,
            tessellations: tessellate,
            shadows,
            renderers,
            formats,
            sbuffer,
            normal_angles: normal_angle,
        };
        let plan = py
            .detach(|| tradeoff::Plan::new(scene.map(Path::new), &request))
            .map_err(study_to_py)?;
        Ok(TradeoffPlan { plan, machine })
    }

    /// The number of groups (tasks).
    fn groups(&self) -> usize {
        self.plan.groups.len()
    }

    /// The number of settings (rows).
    fn settings(&self) -> usize {
        self.plan.settings.len()
    }

    /// The renderers left out of the grid, with why.
    fn skipped(&self) -> Vec<(&'static str, String)> {
        self.plan.skipped.clone()
    }

    /// The rows of group `g` as JSON (none marked Pareto-optimal yet), measured without
    /// the GIL, host times the median of `repeat`.
    #[pyo3(signature = (g, repeat=3))]
    fn measure(&self, py: Python<'_>, g: usize, repeat: u32) -> PyResult<String> {
        if g >= self.plan.groups.len() {
            return Err(usage_error(format!(
                "group {g} of a plan of {}",
                self.plan.groups.len()
            )));
        }
        let rows = interruptible(py, |cancel| {
            self.plan
                .measure_group_until(g, &self.machine, repeat, Some(cancel))
        })?
        .map_err(study_to_py)?;
        serde_json::to_string(&rows).map_err(|e| CwisimError::new_err(e.to_string()))
    }
}

/// Which points `(bus cycles, register bits, RMS error)` are Pareto-optimal, as
/// `tradeoff` marks its rows.
#[pyfunction]
fn pareto(points: Vec<(u64, u32, f64)>) -> Vec<bool> {
    tradeoff::pareto(&points)
}

/// `cwisim fit`: the narrowest fixed-point registers with which `renderer`'s stream for
/// the scene (a file or an embedded name) stays within `max_error` of the f64 array.
/// Returns a dict: `numeric` (the format, as `--numeric` takes it), `error`,
/// `exact_error`, `f64_error`, `registers` (name → `(int_bits, frac_bits, max error with
/// one fraction bit fewer)`), `bits`, `replays`, `instructions`.
#[pyfunction]
#[pyo3(signature = (scene=None, renderer="vanrij", settings=Vec::new(), max_error=1.0/512.0, overflow="saturate", machine=None, threads=0))]
#[allow(clippy::too_many_arguments)] // Python's keywords: the command line's flags
fn fit<'py>(
    py: Python<'py>,
    scene: Option<&str>,
    renderer: &str,
    settings: Vec<(String, String)>,
    max_error: f64,
    overflow: &str,
    machine: Option<&str>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    cwisim_scene::budget::check_threads(threads).map_err(usage_error)?;
    if !(max_error.is_finite() && max_error > 0.0) {
        return Err(usage_error(format!(
            "max_error: the error budget must be finite and > 0, found {max_error}"
        )));
    }
    let overflow = match overflow {
        "saturate" => Overflow::Saturate,
        "wrap" => Overflow::Wrap,
        other => {
            return Err(usage_error(format!(
                "overflow: unknown `{other}`; expected saturate or wrap"
            )))
        }
    };
    let (settings, given) = settings_of(&settings, threads)?;
    let array = array_config("f64", "fast", machine)?;
    let found = interruptible(py, |cancel| {
        let drawn = draw(
            renderer,
            SceneInput::Named(scene.map(Path::new)),
            &given,
            &settings,
        )?;
        fit_scene(
            &*drawn.renderer,
            scene.map(Path::new),
            settings.size,
            &array.machine,
            max_error,
            overflow,
            threads,
            Some(cancel),
        )
    })?
    .map_err(study_to_py)?;
    let f = &found.fit;
    let out = PyDict::new(py);
    out.set_item("numeric", Numeric::Fixed(f.format).to_string())?;
    out.set_item("error", f.error)?;
    out.set_item("exact_error", f.exact_error)?;
    out.set_item("f64_error", f.f64_error)?;
    let registers = PyDict::new(py);
    let mut bits = 0;
    for (k, name) in REGISTERS.iter().enumerate() {
        let qk = q(&f.format, k);
        bits += qk.int_bits + qk.frac_bits;
        registers.set_item(*name, (qk.int_bits, qk.frac_bits, f.one_bit_less[k]))?;
    }
    out.set_item("registers", registers)?;
    out.set_item("bits", bits)?;
    out.set_item("replays", f.runs)?;
    out.set_item("instructions", found.instructions)?;
    Ok(out)
}

/// A phase's figures, for Python.
fn phase_dict<'py>(py: Python<'py>, r: &PhaseRow) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("phase", r.phase)?;
    d.set_item("pixels", r.pixels)?;
    d.set_item("instructions", r.instructions)?;
    d.set_item("regenerated", r.regenerated)?;
    d.set_item("busy_cycles", r.busy_cycles)?;
    d.set_item("cumulative_cycles", r.cumulative_cycles)?;
    d.set_item("worst_line_cycles", r.worst_line_cycles)?;
    d.set_item("late_lines", r.late_lines)?;
    d.set_item("rms", r.rms)?;
    d.set_item("psnr_db", r.psnr)?;
    d.set_item("display_list_bytes", r.display_list_bytes)?;
    Ok(d)
}

/// `cwisim refine`: Bergman et al.'s adaptive refinement of a world scene (a file or an
/// embedded name), each phase a complete frame. `phases` as `--phases` takes them;
/// `settings` those `refine` reads (thresholds, `size`, `tessellate`,
/// `shade_tolerance`, `shadows`). Returns a dict: `phases` and `naive` (one dict per
/// phase: pixels, instructions, regenerated, busy and cumulative cycles, worst line, late
/// lines, RMS and PSNR against the full-quality image, display-list bytes), `frames`
/// (frames × lines × width × channels), `busy_per_line` (frames × lines), `counters`,
/// `polygons`, `highlight` (passing, visible), `line_period`, `frame_buffer_bytes`.
#[pyfunction]
#[pyo3(signature = (scene=None, phases="flat,gouraud,phong,aa", settings=Vec::new(), machine=None, threads=1))]
fn refine<'py>(
    py: Python<'py>,
    scene: Option<&str>,
    phases: &str,
    settings: Vec<(String, String)>,
    machine: Option<&str>,
    threads: usize,
) -> PyResult<Bound<'py, PyDict>> {
    cwisim_scene::budget::check_threads(threads).map_err(usage_error)?;
    let phases = parse_phases(phases).map_err(usage_error)?;
    let (settings, given) = settings_of(&settings, 1)?;
    registry::find("refine")
        .map_err(to_py)?
        .check_given(&given, &settings)
        .map_err(usage_error)?;
    settings.check().map_err(usage_error)?;
    let array = array_config("f64", "fast", machine)?;
    let mut run = interruptible(py, |cancel| {
        let setup = RefineSetup {
            scene: scene.map(Path::new),
            changes: &[],
            settings,
            phases,
            vertex_parts: 1,
            machine: array.machine,
            naive: true,
            cost_maps: false,
            ids: false,
            threads,
            cancel: Some(cancel),
        };
        run_refine(&setup, None, None)
    })?
    .map_err(study_to_py)?;
    let out = PyDict::new(py);
    let rows = PyList::empty(py);
    for r in &run.rows {
        rows.append(phase_dict(py, r)?)?;
    }
    out.set_item("phases", rows)?;
    let naive = PyList::empty(py);
    for r in &run.naive {
        naive.append(phase_dict(py, r)?)?;
    }
    out.set_item("naive", naive)?;
    let frames = run.frames.len();
    let mut data = Vec::with_capacity(frames * run.lines * run.width * run.channels);
    for f in std::mem::take(&mut run.frames) {
        data.extend_from_slice(&f.data);
    }
    out.set_item(
        "frames",
        PyArray1::from_vec(py, data).reshape([frames, run.lines, run.width, run.channels])?,
    )?;
    let busy: Vec<u64> = run.busy_per_line.iter().flatten().copied().collect();
    out.set_item(
        "busy_per_line",
        PyArray1::from_vec(py, busy).reshape([run.busy_per_line.len(), run.lines])?,
    )?;
    let counters = PyDict::new(py);
    for (k, v) in run.counters.iter() {
        counters.set_item(k, v)?;
    }
    out.set_item("counters", counters)?;
    out.set_item("polygons", run.polygons)?;
    out.set_item("highlight", run.highlight)?;
    out.set_item("line_period", run.line_period)?;
    out.set_item("frame_buffer_bytes", run.frame_buffer_bytes)?;
    out.set_item("scene", run.scene)?;
    Ok(out)
}

/// Scanline `line` asked of a trace that outputs only `lines`.
fn beyond_trace(line: u64, lines: u64) -> PyErr {
    usage_error(format!(
        "line {line}: the trace outputs {lines} scanline(s), 0..{lines}"
    ))
}

/// A processor's state, for Python.
fn state_dict<'py>(py: Python<'py>, s: &ProcessorState) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("acc", s.acc.clone())?;
    d.set_item("I", s.reg[0].clone())?;
    d.set_item("dI", s.reg[1].clone())?;
    d.set_item("ddI", s.reg[2].clone())?;
    d.set_item("has", s.has)?;
    d.set_item("locked", s.locked)?;
    d.set_item("masked", s.masked)?;
    d.set_item("negative_enabled", s.negative_enabled)?;
    Ok(d)
}

/// `cwisim history`: every visit of a token to processor `x` on scanline `line` of the
/// trace file `path`, on the cycle-stepped engine, registers in `numeric`. A list of
/// dicts: `cycle`, `index` (the instruction's, in the trace), `instruction` (as the text
/// form writes it), `op`, `addressed`, `before` and `after` (the processor's registers
/// and flags), `note` (what the visit amounted to, when not a plain action),
/// `provenance` (the note the trace attaches to the instruction: which row, polygon,
/// case). A scanline the trace does not reach raises `UsageError`.
#[pyfunction]
#[pyo3(signature = (path, x, line, numeric="f64", machine=None))]
fn history<'py>(
    py: Python<'py>,
    path: &str,
    x: usize,
    line: u64,
    numeric: &str,
    machine: Option<&str>,
) -> PyResult<Bound<'py, PyList>> {
    let array = array_config(numeric, "stepped", machine)?;
    let found = py
        .detach(|| {
            let mut reader = FileReader::open(Path::new(path))?;
            let width = reader.header().width as usize;
            if x >= width {
                return Err(StudyError::Usage(format!(
                    "x {x}: the trace has processors 0..{width}"
                )));
            }
            pixel_history_with_progress(
                &mut reader,
                &array.machine,
                &array.numeric,
                x,
                line,
                &mut |_| {},
            )
        })
        .map_err(study_to_py)?
        .map_err(|lines| beyond_trace(line, lines))?;
    let out = PyList::empty(py);
    for v in &found.visits {
        let d = PyDict::new(py);
        d.set_item("cycle", v.cycle)?;
        d.set_item("index", v.index)?;
        d.set_item("instruction", v.instr.to_string())?;
        d.set_item("op", v.instr.op.name())?;
        d.set_item("addressed", v.addressed)?;
        d.set_item("before", state_dict(py, &v.before)?)?;
        d.set_item("after", state_dict(py, &v.after)?)?;
        d.set_item("note", v.note())?;
        d.set_item(
            "provenance",
            found.provenance(v).map(|n| n.text.to_string()),
        )?;
        out.append(d)?;
    }
    Ok(out)
}

/// `cwisim vcd`: the per-cycle waveform of scanline `line` of the trace file `path`, for
/// processors `first..=last` (on the cycle-stepped engine, registers in `numeric`). A
/// dict: `start` and `end` (the window's cycles), `signals` (`scope.name` → (cycles,
/// values): the value at `start` and at each cycle it changes; bits 0 or 1, words
/// their value or NaN when nothing drives them, reals themselves).
#[pyfunction]
#[pyo3(signature = (path, line, first, last, numeric="f64", machine=None))]
fn waveform<'py>(
    py: Python<'py>,
    path: &str,
    line: u64,
    first: usize,
    last: usize,
    numeric: &str,
    machine: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let array = array_config(numeric, "stepped", machine)?;
    let wave = py
        .detach(|| {
            let mut reader = FileReader::open(Path::new(path))?;
            let width = reader.header().width as usize;
            if first > last || last >= width {
                return Err(StudyError::Usage(format!(
                    "processors {first}..={last}: the trace has processors 0..{width}"
                )));
            }
            record_scanline_with_progress(
                &mut reader,
                &array.machine,
                &array.numeric,
                line,
                first,
                last,
                &mut |_| {},
            )
        })
        .map_err(study_to_py)?
        .map_err(|lines| beyond_trace(line, lines))?;
    let out = PyDict::new(py);
    let (start, end) = wave.window();
    out.set_item("start", start)?;
    out.set_item("end", end)?;
    let signals = PyDict::new(py);
    for (name, cycles, values) in wave.signals() {
        signals.set_item(
            name,
            (
                PyArray1::from_vec(py, cycles),
                PyArray1::from_vec(py, values),
            ),
        )?;
    }
    out.set_item("signals", signals)?;
    Ok(out)
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("CwisimError", py.get_type::<CwisimError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("UsageError", py.get_type::<UsageError>())?;
    m.add_function(wrap_pyfunction!(scenes, m)?)?;
    m.add_function(wrap_pyfunction!(scene_text, m)?)?;
    m.add_function(wrap_pyfunction!(renderers, m)?)?;
    m.add_function(wrap_pyfunction!(setting_names, m)?)?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(opcodes, m)?)?;
    m.add_function(wrap_pyfunction!(emit_stream, m)?)?;
    m.add_function(wrap_pyfunction!(read_trace, m)?)?;
    m.add_function(wrap_pyfunction!(encode_trace, m)?)?;
    m.add_function(wrap_pyfunction!(replay, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(refine, m)?)?;
    m.add_function(wrap_pyfunction!(history, m)?)?;
    m.add_function(wrap_pyfunction!(waveform, m)?)?;
    m.add_function(wrap_pyfunction!(trace_header, m)?)?;
    m.add_function(wrap_pyfunction!(default_formats, m)?)?;
    m.add_function(wrap_pyfunction!(default_tessellations, m)?)?;
    m.add_function(wrap_pyfunction!(pareto, m)?)?;
    m.add_function(wrap_pyfunction!(keyword_spelling_py, m)?)?;
    m.add_class::<TradeoffPlan>()?;
    Ok(())
}
