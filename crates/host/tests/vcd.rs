//! `cwisim vcd` end to end: every dump is read back with `wellen`, a VCD reader that
//! shares no code with the `vcd` crate the command writes through, and held to the
//! replay (`cwisim run --npy` for the values, `--stats-json` for the cycles, both from
//! the fast engine while the dump comes from the cycle-stepped one).
//!
//! What the writer does not check is checked here on the file's text too: the timescale,
//! strictly increasing time stamps, printable and unique identifier codes.

mod common;

use common::{cwisim, cwisim_ok, read, read_npy, scratch, text};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use wellen::{simple::Waveform, SignalValueRef, TimescaleUnit};

fn trace(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../traces")
        .join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path")
}

/// Time stamps and `$var` identifier codes from the file's text, checked: times strictly
/// increase, codes are printable ASCII (33–126) and unique, and every value change names
/// a declared code.
fn check_text(text: &str) -> (Vec<u64>, Vec<String>) {
    let mut times: Vec<u64> = Vec::new();
    let mut ids = Vec::new();
    let mut declared = BTreeSet::new();
    let mut timescales = 0;
    let mut in_defs = true;
    for line in text.lines() {
        let t = line.trim();
        if in_defs {
            if t.starts_with("$var") {
                let f: Vec<&str> = t.split_whitespace().collect();
                assert_eq!(f.len(), 6, "{t}");
                assert_eq!(f[5], "$end", "{t}");
                let id = f[3];
                assert!(!id.is_empty());
                assert!(
                    id.bytes().all(|b| (33..=126).contains(&b)),
                    "identifier {id:?} is not printable ASCII"
                );
                assert!(declared.insert(id.to_string()), "identifier {id:?} twice");
                ids.push(id.to_string());
            } else if t.starts_with("$timescale") {
                timescales += 1;
                assert_eq!(t, "$timescale 1 ns $end");
            } else if t.starts_with("$enddefinitions") {
                in_defs = false;
            }
            continue;
        }
        if let Some(n) = t.strip_prefix('#') {
            let n: u64 = n.parse().expect("a time stamp");
            if let Some(&last) = times.last() {
                assert!(n > last, "time #{n} after #{last}");
            }
            times.push(n);
        } else if t.starts_with('$') || t.is_empty() {
            assert!(
                matches!(t, "$dumpvars" | "$end"),
                "unexpected command {t:?}"
            );
        } else {
            assert!(!times.is_empty(), "a value before the first time stamp");
            let id = match t.as_bytes()[0] {
                b'0' | b'1' | b'x' | b'z' => &t[1..],
                b'b' | b'r' => t.split_once(' ').expect("value and id").1,
                _ => panic!("unexpected line {t:?}"),
            };
            assert!(declared.contains(id), "change of undeclared {id:?}");
        }
    }
    assert_eq!(timescales, 1);
    assert!(!in_defs, "no $enddefinitions");
    (times, ids)
}

/// The dump read back with wellen.
struct Dump {
    wave: Waveform,
    text: String,
    times: Vec<u64>,
}

impl Dump {
    fn read(path: &Path) -> Dump {
        let text = String::from_utf8(read(path)).expect("a VCD is ASCII");
        let (times, _) = check_text(&text);
        let wave = wellen::simple::read(path).expect("wellen reads the dump");
        let ts = wave.hierarchy().timescale().expect("a timescale");
        assert_eq!(ts.factor, 1);
        assert!(matches!(ts.unit, TimescaleUnit::NanoSeconds), "{ts:?}");
        // wellen drops repeated or decreasing time stamps: equal tables mean none were.
        assert_eq!(wave.time_table(), &times[..]);
        Dump { wave, text, times }
    }

    /// The scopes under the top scope `cwisim`.
    fn scopes(&self) -> Vec<String> {
        let h = self.wave.hierarchy();
        let top = h.lookup_scope(&["cwisim"]).expect("the top scope");
        h[top].scopes(h).map(|s| h[s].name(h).to_string()).collect()
    }

    /// Every change of `scope.name`: (time, value).
    fn changes(&mut self, scope: &str, name: &str) -> Vec<(u64, Val)> {
        let h = self.wave.hierarchy();
        let var = h
            .lookup_var(&["cwisim", scope], name)
            .unwrap_or_else(|| panic!("no variable {scope}.{name}"));
        let sig = h[var].signal_ref();
        self.wave.load_signals(&[sig]);
        let times = self.wave.time_table().to_vec();
        let signal = self.wave.get_signal(sig).expect("loaded");
        signal
            .iter_changes()
            .map(|(i, v)| {
                let v = match v {
                    SignalValueRef::Real(r) => Val::Real(r),
                    other => Val::Bits(other.to_bit_string().expect("bits")),
                };
                (times[i as usize], v)
            })
            .collect()
    }

    /// The value of `scope.name` at the end of the window.
    fn last(&mut self, scope: &str, name: &str) -> Val {
        self.changes(scope, name).pop().expect("an initial value").1
    }

    /// The value of `scope.name` at `t`.
    fn at(&mut self, scope: &str, name: &str, t: u64) -> Val {
        self.changes(scope, name)
            .into_iter()
            .take_while(|&(ct, _)| ct <= t)
            .last()
            .expect("a value")
            .1
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Val {
    Real(f64),
    Bits(String),
}

impl Val {
    fn real(&self) -> f64 {
        match self {
            Val::Real(r) => *r,
            Val::Bits(b) => panic!("{b} is not a real"),
        }
    }
    fn int(&self) -> Option<u64> {
        match self {
            Val::Bits(b) if b.bytes().all(|c| c == b'z') => None,
            Val::Bits(b) => Some(u64::from_str_radix(b, 2).expect("binary")),
            Val::Real(r) => panic!("{r} is not a wire"),
        }
    }
}

/// The replay of `trace` with `machine` (extra arguments) by `cwisim run`: the image
/// (shape, values) and, per scanline, `(first_issue, ready)`.
fn replay(dir: &Path, trace: &Path, machine: &[&str]) -> (Vec<u64>, Vec<f64>, Vec<(u64, u64)>) {
    let mut args = vec![
        "run",
        s(trace),
        "--npy",
        "replay.npy",
        "--stats-json",
        "replay.json",
    ];
    args.extend_from_slice(machine);
    cwisim_ok(dir, &args);
    let (shape, values) = read_npy(dir.join("replay.npy"));
    let json: serde_json::Value =
        serde_json::from_slice(&read(dir.join("replay.json"))).expect("JSON");
    let lines = json["stats"]["lines"]
        .as_array()
        .expect("lines")
        .iter()
        .map(|l| {
            (
                l["first_issue"].as_u64().expect("first_issue"),
                l["ready"].as_u64().expect("ready"),
            )
        })
        .collect();
    (shape, values, lines)
}

fn channel_names(name: &str, channels: usize) -> Vec<String> {
    if channels == 1 {
        vec![name.to_string()]
    } else {
        (0..channels).map(|k| format!("{name}_c{k}")).collect()
    }
}

/// Dumps every scanline of `trace` (processors `window`, or all) and checks each dump
/// against the replay: the window of time, the scopes, and every `out` register's final
/// value, channel by channel, bit for bit.
fn check_every_line(name: &str, machine: &[&str], window: Option<(u32, u32)>) {
    let dir = scratch(&format!("vcd-lines-{name}"));
    let t = trace(name);
    let (shape, image, lines) = replay(&dir, &t, machine);
    let (width, channels) = (shape[1] as usize, shape[2] as usize);
    assert_eq!(lines.len() as u64, shape[0]);
    let (from, to) = window.map_or((0, width - 1), |(a, b)| (a as usize, b as usize));
    for (y, &(first_issue, ready)) in lines.iter().enumerate() {
        let y_arg = y.to_string();
        let mut args = vec!["vcd", s(&t), "--line", &y_arg, "-o", "out.vcd"];
        let bounds = window.map(|(a, b)| (a.to_string(), b.to_string()));
        if let Some((a, b)) = &bounds {
            args.extend_from_slice(&["--from", a, "--to", b]);
        }
        args.extend_from_slice(machine);
        let stdout = cwisim_ok(&dir, &args);
        assert!(stdout.is_empty());
        let mut dump = Dump::read(&dir.join("out.vcd"));
        // The window of time: the scanline's first issue to its readiness (fast engine).
        assert_eq!(dump.times.first(), Some(&first_issue), "{name} line {y}");
        assert_eq!(dump.times.last(), Some(&ready), "{name} line {y}");
        let mut expected_scopes = vec!["bus".to_string()];
        expected_scopes.extend((from..=to).map(|p| format!("p{p}")));
        assert_eq!(dump.scopes(), expected_scopes);
        // The bus is issuing at the first cycle.
        assert_eq!(dump.at("bus", "busy", first_issue), Val::Bits("1".into()));
        for p in from..=to {
            let scope = format!("p{p}");
            for (k, out) in channel_names("out", channels).iter().enumerate() {
                let got = dump.last(&scope, out).real();
                let want = image[(y * width + p) * channels + k];
                assert_eq!(
                    got.to_bits(),
                    want.to_bits(),
                    "{name} line {y} {scope}.{out}: {got} != {want}"
                );
            }
        }
    }
}

#[test]
fn gouraud_every_line_reads_back_and_ends_with_the_replayed_scanline() {
    check_every_line("gouraud.cwt", &[], None);
}

#[test]
fn rgb_has_one_real_per_channel_and_each_matches() {
    check_every_line("rgb.cwt", &[], None);
    let dir = scratch("vcd-rgb-names");
    cwisim_ok(
        &dir,
        &["vcd", s(&trace("rgb.cwt")), "--line", "0", "-o", "o.vcd"],
    );
    let mut dump = Dump::read(&dir.join("o.vcd"));
    let h = dump.wave.hierarchy();
    for (scope, names) in [
        (
            "bus",
            vec!["I_c0", "I_c1", "I_c2", "ddI_c2", "opcode", "busy"],
        ),
        (
            "p7",
            vec!["acc_c0", "acc_c2", "I_c1", "dI_c0", "ddI_c2", "out_c1"],
        ),
    ] {
        for n in names {
            assert!(h.lookup_var(&["cwisim", scope], n).is_some(), "{scope}.{n}");
        }
    }
    assert!(h.lookup_var(&["cwisim", "p7"], "acc").is_none());
    let _ = dump.last("p7", "out_c2").real();
}

#[test]
fn visibility_preload_periodic_negative_and_a_window_match_the_replay() {
    check_every_line("visibility.cwt", &[], None);
    check_every_line("preload.cwt", &[], None);
    check_every_line("periodic.cwt", &[], None);
    check_every_line("negative.cwt", &[], Some((3, 11)));
}

#[test]
fn late_lines_and_slower_hops_still_end_with_the_scanline() {
    // overrun: lines miss their deadline, so the next Refresh may start before the
    // scanline is ready; `out` must still hold this scanline's values.
    let machine = trace("overrun.machine.json");
    check_every_line("overrun.cwt", &["--machine", s(&machine)], None);
    check_every_line(
        "flat.cwt",
        &["--set", "hop_cycles=3", "--set", "value_cycles=2"],
        None,
    );
}

#[test]
fn a_token_stays_hop_cycles_in_each_processor() {
    let dir = scratch("vcd-hop");
    let t = trace("gouraud.cwt");
    for hop in [1u64, 2, 3] {
        let set = format!("hop_cycles={hop}");
        cwisim_ok(
            &dir,
            &["vcd", s(&t), "--line", "2", "-o", "h.vcd", "--set", &set],
        );
        let mut dump = Dump::read(&dir.join("h.vcd"));
        let end = *dump.times.last().expect("times");
        let mut seen = 0;
        for p in 0..16 {
            let changes = dump.changes(&format!("p{p}"), "token");
            // Skip the initial value: that token may have arrived before the window.
            for pair in changes[1..].windows(2) {
                if pair[0].1.int().is_some() {
                    assert!(pair[1].0 - pair[0].0 >= hop, "p{p}: {pair:?}");
                    seen += 1;
                }
            }
            if let Some(&(t0, ref v)) = changes.last() {
                if changes.len() > 1 && v.int().is_some() {
                    assert!(end - t0 < hop, "p{p}: a token still at the end: {t0}");
                }
            }
        }
        assert!(seen > 0, "hop {hop}: no token seen");
    }
}

#[test]
fn the_bus_shows_each_instruction_from_issue_to_entry() {
    // gouraud line 1: `Eval2 3 10 0.125 0.0625` is instruction #2, issued at cycle 4
    // and entering the array at 7; the Refresh (#3) issues at 32679 and enters at 32680
    // (`cwisim dump traces/gouraud.cwt --lines 1`).
    let dir = scratch("vcd-bus");
    cwisim_ok(
        &dir,
        &[
            "vcd",
            s(&trace("gouraud.cwt")),
            "--line",
            "1",
            "-o",
            "b.vcd",
        ],
    );
    let mut d = Dump::read(&dir.join("b.vcd"));
    assert_eq!(d.times[0], 4);
    assert_eq!(d.at("bus", "opcode", 4).int(), Some(0x09));
    assert_eq!(d.at("bus", "x", 4).int(), Some(3));
    assert_eq!(d.at("bus", "dx", 4).int(), Some(10));
    assert_eq!(d.at("bus", "I", 4).real(), 0.125);
    assert_eq!(d.at("bus", "dI", 4).real(), 0.0625);
    assert_eq!(d.at("bus", "ddI", 4).real(), 0.0);
    assert_eq!(d.at("bus", "index", 4).int(), Some(2));
    assert_eq!(d.at("bus", "busy", 6).int(), Some(1));
    // Idle: opcode 0, operands undriven, the last instruction number kept.
    assert_eq!(d.at("bus", "busy", 7).int(), Some(0));
    assert_eq!(d.at("bus", "opcode", 7).int(), Some(0));
    assert_eq!(d.at("bus", "x", 7).int(), None);
    assert_eq!(d.at("bus", "index", 7).int(), Some(2));
    // The Refresh: no operands.
    assert_eq!(d.at("bus", "opcode", 32679).int(), Some(0x0D));
    assert_eq!(d.at("bus", "x", 32679).int(), None);
    assert_eq!(d.at("bus", "index", 32679).int(), Some(3));
    // The Eval2's token acts in p5 at 7 + 5 and leaves the accumulator at I + 2 dI.
    assert_eq!(d.at("p5", "token", 12).int(), Some(2));
    assert_eq!(d.at("p5", "acc", 12).real(), 0.125 + 2.0 * 0.0625);
    // The Refresh passes p5 at 32680 + 5: out takes the accumulator, which resets.
    assert_eq!(d.at("p5", "out", 32684).real(), 0.0);
    assert_eq!(d.at("p5", "out", 32685).real(), 0.25);
    assert_eq!(d.at("p5", "acc", 32685).real(), 0.0);
    assert!(d.text.contains("One time unit is one array clock cycle"));
}

/// The value at `t` in a list of changes.
fn value_at(changes: &[(u64, Val)], t: u64) -> Val {
    changes
        .iter()
        .take_while(|&&(ct, _)| ct <= t)
        .last()
        .expect("a value by then")
        .1
        .clone()
}

#[test]
fn processors_start_with_their_state_at_the_window_start() {
    // Scanline Y's window starts while scanline Y-1's Refresh is still in the array, so
    // the two dumps overlap in time; there every register, flag, token and the bus must
    // agree, which they can only if each dump starts from the state the processors had.
    for name in ["gouraud.cwt", "preload.cwt", "visibility.cwt", "rgb.cwt"] {
        let dir = scratch(&format!("vcd-initial-{name}"));
        let t = trace(name);
        let (shape, _, lines) = replay(&dir, &t, &[]);
        let channels = shape[2] as usize;
        let mut names: Vec<String> = Vec::new();
        for n in ["acc", "I", "dI", "ddI"] {
            names.extend(channel_names(n, channels));
        }
        for n in [
            "has_I", "has_dI", "has_ddI", "locked", "masked", "neg", "token",
        ] {
            names.push(n.to_string());
        }
        let mut dumps = Vec::new();
        for y in 0..lines.len() {
            let out = format!("l{y}.vcd");
            cwisim_ok(&dir, &["vcd", s(&t), "--line", &y.to_string(), "-o", &out]);
            dumps.push(Dump::read(&dir.join(out)));
        }
        let mut overlaps = 0;
        for y in 1..dumps.len() {
            let (start, end) = (dumps[y].times[0], *dumps[y - 1].times.last().expect("end"));
            if y == 1 {
                // Nothing happened before line 0's first instruction: all +0.0.
                let first = dumps[0].times[0];
                for p in 0..16 {
                    for n in ["acc", "I", "dI", "ddI"] {
                        for n in channel_names(n, channels) {
                            let v = dumps[0].at(&format!("p{p}"), &n, first).real();
                            assert_eq!(v.to_bits(), 0.0f64.to_bits(), "p{p}.{n}");
                        }
                    }
                }
            }
            // A scanline whose only instruction is its Refresh waits for the display and
            // may start after the previous one left: no overlap then.
            if start > end {
                continue;
            }
            for p in 0..16 {
                let scope = format!("p{p}");
                for n in &names {
                    let a = dumps[y - 1].changes(&scope, n);
                    let b = dumps[y].changes(&scope, n);
                    for t in start..=end {
                        assert_eq!(
                            value_at(&a, t),
                            value_at(&b, t),
                            "{name}: {scope}.{n} at {t} in lines {} and {y}",
                            y - 1
                        );
                        overlaps += 1;
                    }
                }
            }
            for n in ["opcode", "x", "dx", "index", "busy"] {
                let a = dumps[y - 1].changes("bus", n);
                let b = dumps[y].changes("bus", n);
                for t in start..=end {
                    assert_eq!(value_at(&a, t), value_at(&b, t), "{name}: bus.{n} at {t}");
                }
            }
        }
        assert!(overlaps > 0, "{name}");
    }
}

#[test]
fn a_window_keeps_the_file_small() {
    let dir = scratch("vcd-window");
    let t = trace("gouraud.cwt");
    cwisim_ok(&dir, &["vcd", s(&t), "--line", "1", "-o", "all.vcd"]);
    cwisim_ok(
        &dir,
        &[
            "vcd",
            s(&t),
            "--line",
            "1",
            "--from",
            "2",
            "--to",
            "8",
            "-o",
            "some.vcd",
        ],
    );
    cwisim_ok(
        &dir,
        &[
            "vcd",
            s(&t),
            "--line",
            "1",
            "--from",
            "5",
            "--to",
            "5",
            "-o",
            "one.vcd",
        ],
    );
    let all = Dump::read(&dir.join("all.vcd"));
    let mut some = Dump::read(&dir.join("some.vcd"));
    let one = Dump::read(&dir.join("one.vcd"));
    assert_eq!(all.scopes().len(), 17);
    assert_eq!(
        some.scopes(),
        ["bus", "p2", "p3", "p4", "p5", "p6", "p7", "p8"]
    );
    assert_eq!(one.scopes(), ["bus", "p5"]);
    let size = |n: &str| read(dir.join(n)).len();
    assert!(
        size("some.vcd") < size("all.vcd") * 3 / 5,
        "{}",
        size("some.vcd")
    );
    assert!(size("one.vcd") < size("some.vcd"));
    // The same processor gives the same values in both.
    let mut all = all;
    for p in 2..=8 {
        let scope = format!("p{p}");
        for n in ["acc", "out", "token", "locked"] {
            assert_eq!(
                all.changes(&scope, n),
                some.changes(&scope, n),
                "{scope}.{n}"
            );
        }
    }
    assert_eq!(all.changes("bus", "opcode"), some.changes("bus", "opcode"));
}

#[test]
fn the_dump_is_the_same_byte_for_byte_every_run() {
    let dir = scratch("vcd-determinism");
    let t = trace("rgb.cwt");
    cwisim_ok(&dir, &["vcd", s(&t), "--line", "1", "-o", "a.vcd"]);
    cwisim_ok(&dir, &["vcd", s(&t), "--line", "1", "-o", "b.vcd"]);
    let a = read(dir.join("a.vcd"));
    assert!(!a.is_empty());
    assert_eq!(a, read(dir.join("b.vcd")));
    // No date, no path.
    let text = String::from_utf8(a).expect("ASCII");
    assert!(!text.contains("$date"));
    assert!(!text.contains("rgb.cwt"));
}

#[test]
fn wide_arrays_need_a_window() {
    let dir = scratch("vcd-wide");
    std::fs::write(
        dir.join("wide.cwt"),
        "cwisim-trace version=1 width=600 lines=1 channels=1\nEval2 60 30 0.5 0.25\nRefresh\n",
    )
    .expect("write trace");
    let out = cwisim(&dir, &["vcd", "wide.cwt", "--line", "0", "-o", "w.vcd"]);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert!(stdout.is_empty());
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("600 processors wide"), "{stderr}");
    assert!(stderr.contains("--x X0..X1"), "{stderr}");
    assert!(!dir.join("w.vcd").exists());
    // A window, or one bound (the other defaults to the array's end).
    cwisim_ok(
        &dir,
        &[
            "vcd", "wide.cwt", "--line", "0", "--from", "58", "--to", "92", "-o", "w.vcd",
        ],
    );
    let mut d = Dump::read(&dir.join("w.vcd"));
    assert_eq!(d.scopes().len(), 1 + 35);
    assert_eq!(d.last("p60", "out").real(), 0.5);
    assert_eq!(d.last("p89", "out").real(), 0.5 + 29.0 * 0.25);
    assert_eq!(d.last("p90", "out").real(), 0.0);
    cwisim_ok(
        &dir,
        &[
            "vcd", "wide.cwt", "--line", "0", "--from", "90", "-o", "w.vcd",
        ],
    );
    assert_eq!(Dump::read(&dir.join("w.vcd")).scopes().len(), 1 + 510);
    // the same windows as one range, --x (the old --from/--to are hidden aliases)
    let before = std::fs::read(dir.join("w.vcd")).expect("vcd");
    cwisim_ok(
        &dir,
        &[
            "vcd", "wide.cwt", "--line", "0", "--x", "90..", "-o", "w.vcd",
        ],
    );
    assert_eq!(std::fs::read(dir.join("w.vcd")).expect("vcd"), before);
    cwisim_ok(
        &dir,
        &[
            "vcd", "wide.cwt", "--line", "0", "--x", "58..93", "-o", "w.vcd",
        ],
    );
    assert_eq!(Dump::read(&dir.join("w.vcd")).scopes().len(), 1 + 35);
    let window = std::fs::read(dir.join("w.vcd")).expect("vcd");
    for same in ["58..=92", "58-92"] {
        cwisim_ok(
            &dir,
            &["vcd", "wide.cwt", "--line", "0", "--x", same, "-o", "w.vcd"],
        );
        assert_eq!(
            std::fs::read(dir.join("w.vcd")).expect("vcd"),
            window,
            "{same}"
        );
    }
    let out = cwisim(
        &dir,
        &[
            "vcd", "wide.cwt", "--line", "0", "--x", "1..3", "--from", "1", "-o", "w.vcd",
        ],
    );
    assert_eq!(out.status.code(), Some(2), "--x and --from conflict");
}

/// Runs `cwisim ARGS` expecting exit 2, one `error:` line containing `needle`, and no
/// output file.
fn refused(dir: &Path, args: &[&str], needle: &str) {
    let out = cwisim(dir, args);
    let (stdout, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stdout.is_empty(), "{args:?}: {stdout}");
    assert_eq!(stderr.lines().count(), 1, "{args:?}: {stderr}");
    assert!(stderr.starts_with("error: "), "{args:?}: {stderr}");
    assert!(stderr.contains(needle), "{args:?}: {stderr}");
    let names: Vec<_> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert!(names.is_empty(), "{args:?} left {names:?}");
}

#[test]
fn bad_inputs_exit_2_with_one_error_line_and_no_file() {
    let dir = scratch("vcd-bad");
    let t = trace("gouraud.cwt");
    let t = s(&t);
    refused(
        &dir,
        &["vcd", t, "--line", "6", "-o", "x.vcd"],
        "outputs only 6 scanline(s) (0..=5)",
    );
    refused(
        &dir,
        &["vcd", t, "--line", "1000000", "-o", "x.vcd"],
        "outputs only 6 scanline(s)",
    );
    refused(
        &dir,
        &[
            "vcd", t, "--line", "0", "--from", "10", "--to", "16", "-o", "x.vcd",
        ],
        "outside the array",
    );
    refused(
        &dir,
        &["vcd", t, "--line", "0", "--from", "16", "-o", "x.vcd"],
        "processors 0..=15",
    );
    refused(
        &dir,
        &[
            "vcd", t, "--line", "0", "--from", "9", "--to", "3", "-o", "x.vcd",
        ],
        "X0 < X1",
    );
    refused(
        &dir,
        &["vcd", "missing.cwt", "--line", "0", "-o", "x.vcd"],
        "missing.cwt: cannot open",
    );
    refused(
        &dir,
        &[
            "vcd",
            t,
            "--line",
            "0",
            "-o",
            "x.vcd",
            "--set",
            "hop_cycles=0",
        ],
        "hop_cycles",
    );
    // A trace with no Refresh is incomplete.
    let empty = scratch("vcd-bad-empty");
    std::fs::write(
        empty.join("t.cwt"),
        "cwisim-trace version=1 width=4 lines=1 channels=1\nEval1 0 4 1.0\n",
    )
    .expect("write");
    let out = cwisim(&empty, &["vcd", "t.cwt", "--line", "0", "-o", "x.vcd"]);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr,
        "error: t.cwt: the trace ends before its first scanline (no Refresh; the header \
announces 1 line per frame): it is incomplete (cut short?); the file ends at byte 64\n"
    );
    assert!(!empty.join("x.vcd").exists());
    // Usage errors of the parser itself.
    let out = cwisim(&dir, &["vcd", t, "-o", "x.vcd"]);
    assert_eq!(out.status.code(), Some(2), "--line is required");
}

#[test]
fn the_output_may_not_overwrite_the_trace() {
    let dir = scratch("vcd-overwrite");
    let small = "cwisim-trace version=1 width=4 lines=1 channels=1\nEval1 0 4 1.0\nRefresh\n";
    std::fs::write(dir.join("t.cwt"), small).expect("write");
    let out = cwisim(&dir, &["vcd", "t.cwt", "--line", "0", "-o", "./t.cwt"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(read(dir.join("t.cwt")), small.as_bytes());
}

#[test]
fn help_documents_the_window_and_the_signals() {
    let dir = scratch("vcd-help");
    let flat = |s: String| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let out = flat(cwisim_ok(&dir, &["vcd", "--help"]));
    for needle in [
        "A..=B",
        "at most 512 processors",
        "one array clock cycle",
        "Examples:",
        "--machine",
        "--set",
    ] {
        assert!(out.contains(needle), "{needle}: {out}");
    }
}
