//! # cwisim-isa — the CWI X-processor instruction set
//!
//! The fourteen scanline commands of van Rij's report (CS-R9427, section 1.4) that the
//! Y-processors send to the one-dimensional array of X-processors, and the trace files
//! that carry them.
//!
//! * [`Opcode`] — the one declaration of the instruction set: code, name and operand
//!   signature of each opcode. Every codec is driven by it.
//! * [`Instruction`] / [`Intensity`] — an instruction with its operands; intensities are
//!   vectors of the trace's channel count (1 grey, 3 RGB).
//! * [`TraceHeader`] — format version, array width, scanlines per frame, channels.
//! * Three encodings, chosen by extension ([`Encoding`]): [`text`] (`.cwt`), [`jsonl`]
//!   (`.jsonl`), [`binary`] (`.cwb`). All are lossless (f64 bit-exact) and interconvert.
//! * [`PackedStream`] — instructions buffered in memory at the size of the values they
//!   carry (a band of scanlines handed from one thread to another).
//! * [`CheckedStream`] — instructions checked once against a header as they are
//!   appended, so that the array executes them without checking them again.
//! * [`note`] — where an instruction came from: the note a trace attaches to it (a
//!   renderer's comment above its instructions in `.cwt`, `"note"` in `.jsonl`), handed
//!   over by [`TraceRead::note`].
//! * [`TraceError`] — every decoding fault is typed ([`ErrorKind`]), located
//!   ([`Location`]: line and column, or byte offset) and says what was expected.
//!
//! The semantics of each instruction are in `docs/ISA.md`; the simulator is `cwisim-xproc`.
//!
//! ```
//! use cwisim_isa::{Encoding, Instruction, Intensity, TraceHeader, io::read_all};
//! let header = TraceHeader::new(16, 2, 1).unwrap();
//! let mut bytes = Vec::new();
//! {
//!     let mut w = Encoding::Binary.writer(&mut bytes, &header).unwrap();
//!     w.write(&Instruction::eval2(0, 8, Intensity::grey(0.25), Intensity::grey(0.125))).unwrap();
//!     w.write(&Instruction::refresh()).unwrap();
//!     w.finish().unwrap();
//! }
//! let mut r = Encoding::Binary.reader(&bytes[..]).unwrap();
//! assert_eq!(read_all(&mut *r).unwrap()[0].to_string(), "Eval2 0 8 0.25 0.125");
//! ```

#![warn(missing_docs)]

pub mod binary;
pub mod checked;
pub mod encoding;
pub mod error;
pub mod header;
pub mod instruction;
pub mod io;
pub mod jsonl;
pub mod note;
pub mod opcode;
pub mod packed;
pub mod text;

pub use checked::{refusal, CheckedStream, Unfit};
pub use encoding::{create_trace, Completeness, Encoding, FileReader, Incomplete};
pub use error::{printable, ErrorKind, Location, TraceError};
pub use header::{HeaderFault, TraceHeader, FORMAT_VERSION, MAX_CHANNELS, MAX_LINES, MAX_WIDTH};
pub use instruction::{Instruction, Intensity, OperandError};
pub use io::{TraceRead, TraceWrite};
pub use note::{Note, NoteTable};
pub use opcode::{Opcode, OperandKind};
pub use packed::PackedStream;
