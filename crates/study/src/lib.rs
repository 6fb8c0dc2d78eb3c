//! # cwisim-study — studying what the array does, without a command line
//!
//! The measuring and drawing behind `cwisim`'s study commands, as a library (no clap, no
//! files: callers choose where results go):
//!
//! * [`cost`] — cost maps: per pixel, how many instructions addressed it on its scanline,
//!   counted from the stream alone; their heat maps and `.npy` form.
//! * [`plot`] — PNG plots with an embedded font (the same bytes on every machine), and the
//!   stats chart: bus cycles per scanline by opcode group against the line period.
//! * [`tradeoff`] — one scene over a grid of renderers and settings, each measured
//!   against the exact image, with the Pareto front; [`tradeoff_plot`] draws it.
//! * [`refine`] — Bergman et al.'s adaptive refinement measured phase by phase against
//!   the full-quality image and the naive sequence; [`refine_report`] its table, CSV and
//!   sweeps, [`refine_plot`] its chart; [`refine_session`] an interactive session (a
//!   script of user events, the refinement restarted at each).
//! * [`fit`] — the narrowest fixed-point registers within an error budget.
//! * [`texture_cost`] — what a texture's frequency costs the array, against the filter
//!   and the span tolerance, with its chart.
//! * [`history`] — one pixel's history: every instruction that reached it on a scanline,
//!   registers before and after; [`vcd`] — a scanline's per-cycle waveform as a Value
//!   Change Dump; both from the cycle-stepped engine's probe. [`until`] ends a trace
//!   after a given scanline; [`provenance`] keeps the notes a trace attaches to its
//!   instructions (where each came from) through them.
//! * [`inspect`] — frames (one, a range, or two runs A/B) as one self-contained HTML page: the image with overlays, the
//!   scanline timeline and disassembly, every pixel history of a window.
//! * [`error`] — [`StudyError`].

#![warn(missing_docs)]

pub mod cost;
pub mod error;
pub mod fit;
pub mod history;
pub mod inspect;
pub mod parallel;
pub mod plot;
pub mod provenance;
pub mod refine;
pub mod refine_ids;
pub mod refine_plot;
pub mod refine_report;
pub mod refine_session;
pub mod texture_cost;
pub mod tradeoff;
pub mod tradeoff_plot;
pub mod until;
pub mod vcd;

pub use error::StudyError;

/// What the tests of the stepped window share: a trace that leaves state across its
/// scanlines, and machines with and without scanlines in flight together.
#[cfg(test)]
pub(crate) mod window_tests {
    use cwisim_isa::text::{format_header, format_instruction, TextReader};
    use cwisim_isa::{Instruction, Intensity, TraceHeader};
    use cwisim_xproc::Machine;

    /// 12 scanlines of 16 pixels, 3 per frame: ramps, preloads left unconsumed across a
    /// `Refresh` (their values stay), `Eval0` locks, `Dis` masks, `Acc_mode` on for some
    /// scanlines, an empty scanline, and instructions after the last `Refresh`.
    pub(crate) fn trace() -> String {
        let header = TraceHeader::new(16, 3, 1).unwrap();
        let g = Intensity::grey;
        let mut out = vec![format_header(&header)];
        let mut push = |i: Instruction| out.push(format_instruction(&i));
        for line in 0..12u32 {
            if line == 7 {
                push(Instruction::refresh());
                continue;
            }
            push(Instruction::set_pi(line % 4, 5, g(0.25 * f64::from(line))));
            push(Instruction::set_di(line % 16, g(-0.125)));
            push(Instruction::eval0(3, 2, g(0.75)));
            push(Instruction::dis(9, 3));
            push(Instruction::eval2(0, 16, g(0.5), g(-0.0625)));
            push(Instruction::eval1(line % 8, 6, g(-0.25)));
            if line % 3 == 1 {
                push(Instruction::acc_mode());
            }
            push(Instruction::refresh());
        }
        push(Instruction::eval1(0, 4, g(1.0)));
        out.join("\n") + "\n"
    }

    /// A reader of [`trace`].
    pub(crate) fn reader(text: &str) -> TextReader<&[u8]> {
        TextReader::new(text.as_bytes()).unwrap()
    }

    /// A machine whose `Refresh`es wait for the display (no two scanlines in the array
    /// together), and one whose line period is shorter than a traversal.
    pub(crate) fn machines() -> [Machine; 2] {
        [
            Machine {
                line_period_cycles: Some(400),
                ..Machine::default()
            },
            Machine {
                hop_cycles: 3,
                line_period_cycles: Some(25),
                vblank_lines: 1,
                ..Machine::default()
            },
        ]
    }
}
