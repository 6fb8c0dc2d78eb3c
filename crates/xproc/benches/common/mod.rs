//! The synthetic frames of the array's benchmark (`benches/array.rs`), shared with
//! `examples/eval_costs.rs` (which includes this file by path): the same instructions in
//! both, from one deterministic generator.

use cwisim_isa::{Instruction, Intensity};

/// A small deterministic generator (xorshift64*), so the frames are the same every run.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Short spans, as the edge pixels of a box-filtered scene produce: per scanline 64
/// `Eval`s of 4–16 processors each (~640 processor updates), orders 1, 2, 3 in
/// proportions 1:2:1, no preloads, then a `Refresh`. `order` (1–3) gives every `Eval` that
/// order, and `dx` that length, instead; the rest of the frame (positions, values) is
/// drawn as without them.
pub fn short_spans(
    width: u32,
    lines: u32,
    order: Option<u64>,
    dx: Option<u32>,
) -> Vec<Instruction> {
    let mut rng = Rng(0xD1B5_4A32_D192_ED03);
    let mut out = Vec::new();
    let g = Intensity::grey;
    for _ in 0..lines {
        for _ in 0..64 {
            let random_dx = 4 + rng.below(13) as u32;
            let dx = dx.unwrap_or(random_dx);
            let x = rng.below(u64::from(width - dx + 1)) as u32;
            let (i, di, ddi) = (
                rng.unit(),
                (rng.unit() - 0.5) / 16.0,
                (rng.unit() - 0.5) / 256.0,
            );
            let mix = match rng.below(4) {
                0 => 1,
                1 => 3,
                _ => 2,
            };
            out.push(match order.unwrap_or(mix) {
                1 => Instruction::eval1(x, dx, g(i)),
                3 => Instruction::eval3(x, dx, g(i), g(di), g(ddi)),
                _ => Instruction::eval2(x, dx, g(i), g(di)),
            });
        }
        out.push(Instruction::refresh());
    }
    out
}
