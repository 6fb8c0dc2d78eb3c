//! What stepping only the scanlines asked for saves: `pixel_history` and `record_scanline`
//! of a trace's last scanline, against the cycle-stepped replay over the whole trace
//! they made before (`replay_probed` with the same probe's watch, over the same reader).
//!
//! ```sh
//! cargo run --release -p cwisim-study --example stepped_window -- 3000 3 10
//! ```
//!
//! Arguments: the number of `Refresh` instructions (scanlines) of the trace (a header
//! of 16 processors and one line per frame, the default machine: each scanline waits a
//! frame, 1.67 million cycles, for the display), the samples of the whole-trace replay
//! (0 skips it), and the samples of the windowed one. Prints the median of each, and the
//! ratio.

use cwisim_isa::text::TextReader;
use cwisim_isa::{Instruction, TraceRead};
use cwisim_study::history::pixel_history;
use cwisim_study::until::UntilLine;
use cwisim_study::vcd::record_scanline;
use cwisim_xproc::{replay_probed, Machine, NullSink, Probe, ProcessorState};
use std::time::{Duration, Instant};

/// Watches processors `from..=to` and keeps their visits of scanline `line`: what the
/// probes of `pixel_history` and `record_scanline` watch.
struct Watch {
    from: usize,
    to: usize,
    line: u64,
    visits: usize,
}

impl Probe for Watch {
    fn watches(&self, p: usize) -> bool {
        (self.from..=self.to).contains(&p)
    }
    fn visit(
        &mut self,
        _cycle: u64,
        _p: usize,
        _index: u64,
        line: u64,
        _instr: &Instruction,
        _addressed: bool,
        _before: &ProcessorState,
        _after: &ProcessorState,
    ) {
        self.visits += usize::from(line == self.line);
    }
}

fn median(mut samples: Vec<Duration>) -> Duration {
    samples.sort();
    samples[samples.len() / 2]
}

/// `n` runs of `f`, timed; the median.
fn time(n: usize, mut f: impl FnMut()) -> Option<Duration> {
    (n > 0).then(|| {
        median(
            (0..n)
                .map(|_| {
                    let t = Instant::now();
                    f();
                    t.elapsed()
                })
                .collect(),
        )
    })
}

fn main() {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a whole number"))
        .collect();
    let lines = args.first().copied().unwrap_or(3000);
    let (before_n, after_n) = (
        args.get(1).copied().unwrap_or(3) as usize,
        args.get(2).copied().unwrap_or(10) as usize,
    );
    let mut text = String::from("cwisim-trace version=1 width=16 lines=1 channels=1\n");
    for _ in 0..lines {
        text.push_str("Refresh\n");
    }
    let reader = || TextReader::new(text.as_bytes()).expect("a valid trace");
    let machine = Machine::default();
    let (x, y) = (7usize, lines - 1);
    println!(
        "trace: 16 processors, 1 line per frame, {lines} Refresh ({} bytes); last scanline {y}",
        text.len()
    );

    for (name, from, to) in [("pixel_history", x, x), ("record_scanline", 0, 15)] {
        let before = time(before_n, || {
            let mut file = reader();
            let mut watch = Watch {
                from,
                to,
                line: y,
                visits: 0,
            };
            let mut until = UntilLine::new(&mut file, Some(y));
            replay_probed::<f64>(&mut until, &machine, &mut watch, &mut NullSink)
                .expect("replayed");
            assert!(watch.visits > 0);
        });
        let after = time(after_n, || {
            let mut file = reader();
            if name == "pixel_history" {
                let visits = pixel_history(&mut file, &machine, x, y).expect("replayed");
                assert!(!visits.expect("the scanline is in the trace").is_empty());
            } else {
                let wave = record_scanline(&mut file, &machine, y, from, to).expect("replayed");
                assert!(wave.is_ok());
            }
            assert!(file.next_instruction().expect("read").is_none());
        });
        let show = |d: Option<Duration>| d.map_or("-".to_string(), |d| format!("{d:.3?}"));
        let ratio = match (before, after) {
            (Some(b), Some(a)) => format!("{:.0}×", b.as_secs_f64() / a.as_secs_f64()),
            _ => "-".to_string(),
        };
        println!(
            "{name:<16} whole trace stepped: {:>10} (median of {before_n})   \
             window stepped: {:>10} (median of {after_n})   faster: {ratio}",
            show(before),
            show(after),
        );
    }
}
