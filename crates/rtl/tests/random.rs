//! Random traces (proptest: eight cases, every opcode, random narrow formats that
//! overflow, random machines with late scanlines) co-simulated in Icarus Verilog against
//! the stepped engine, on the design of all fourteen opcodes.

mod common;

use common::{hdl_tools, scratch};
use cwisim_isa::{Instruction, Intensity, Opcode, TraceHeader};
use cwisim_rtl::verilog::Watch;
use cwisim_rtl::{all_opcodes, cosimulate, BusTiming, Design, Simulator};
use cwisim_xproc::{FixedFormat, Machine, Overflow, Q};
use proptest::prelude::*;

fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(0.5),
        Just(-0.25),
        -3.0..3.0f64,
        (-64i32..64).prop_map(|k| f64::from(k) / 16.0),
    ]
}

/// One instruction of any opcode but `Refresh`, valid for `width` and `channels`.
fn instruction(width: u32, channels: usize) -> impl Strategy<Value = Instruction> {
    let ops: Vec<Opcode> = Opcode::ALL
        .iter()
        .copied()
        .filter(|o| *o != Opcode::Refresh)
        .collect();
    (
        proptest::sample::select(ops),
        0..width,
        0..=width,
        proptest::collection::vec(value(), 3 * channels),
    )
        .prop_map(move |(op, x, n, v)| {
            let dx = n.min(width - x); // a range within the array
            let period = n.max(1);
            let c = channels;
            let iv = |s: usize| Intensity::new(&v[s * c..s * c + c]);
            match op {
                Opcode::SetI => Instruction::set_i(x, iv(0)),
                Opcode::SetdI => Instruction::set_di(x, iv(1)),
                Opcode::SetddI => Instruction::set_ddi(x, iv(2)),
                Opcode::SetPI => Instruction::set_pi(x, period, iv(0)),
                Opcode::SetPdI => Instruction::set_pdi(x, period, iv(1)),
                Opcode::SetPddI => Instruction::set_pddi(x, period, iv(2)),
                Opcode::Eval0 => Instruction::eval0(x, dx, iv(0)),
                Opcode::Eval1 => Instruction::eval1(x, dx, iv(0)),
                Opcode::Eval2 => Instruction::eval2(x, dx, iv(0), iv(1)),
                Opcode::Eval3 => Instruction::eval3(x, dx, iv(0), iv(1), iv(2)),
                Opcode::Dis => Instruction::dis(x, dx),
                Opcode::AccMode => Instruction::acc_mode(),
                Opcode::Nop | Opcode::Refresh => Instruction::nop(),
            }
        })
}

fn q() -> impl Strategy<Value = Q> {
    (1u32..4, 0u32..9).prop_map(|(m, n)| Q::new(m, n).unwrap())
}

fn case() -> impl Strategy<Value = (TraceHeader, Vec<Instruction>, FixedFormat, Machine)> {
    (1u32..10, 1usize..3, 1u32..3).prop_flat_map(|(width, channels, lines)| {
        let line = proptest::collection::vec(instruction(width, channels), 0..10);
        (
            proptest::collection::vec(line, lines as usize * 2..=lines as usize * 2),
            (q(), q(), q(), q(), any::<bool>()),
            (1u64..3, 1u32..3, 20u64..200),
        )
            .prop_map(
                move |(body, (i, di, ddi, acc, wrap), (hop, cost, period))| {
                    let header = TraceHeader::new(width, lines, channels as u8).unwrap();
                    let mut trace = Vec::new();
                    for l in body {
                        trace.extend(l);
                        trace.push(Instruction::refresh());
                    }
                    let format = FixedFormat {
                        i,
                        di,
                        ddi,
                        acc,
                        overflow: if wrap {
                            Overflow::Wrap
                        } else {
                            Overflow::Saturate
                        },
                    };
                    let machine = Machine::default()
                        .with_overrides(&[
                            format!("hop_cycles={hop}"),
                            format!("opcode_cycles.Eval3={cost}"),
                            format!("line_period_cycles={period}"),
                            "vblank_lines=1".into(),
                        ])
                        .unwrap();
                    (header, trace, format, machine)
                },
            )
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 8, ..ProptestConfig::default() })]

    #[test]
    fn random_traces_agree_bit_and_cycle_for_cycle((header, trace, format, machine) in case()) {
        if !hdl_tools("the Icarus co-simulation of random traces") {
            return Ok(());
        }
        let d = Design::new(
            format,
            all_opcodes(),
            header.width,
            header.channel_count(),
            BusTiming::new(&machine, &header).unwrap(),
        )
        .unwrap();
        let dir = scratch("random");
        let out = cosimulate(&d, &header, &trace, &machine, &Watch::all(d.width), Simulator::Icarus, &dir)
            .unwrap();
        if let Err(m) = out.result {
            prop_assert!(false, "{format}: {m} (files in {})", dir.display());
        }
    }
}
