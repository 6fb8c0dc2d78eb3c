//! Every example in `traces/` replays to its checked-in expected output
//! (`traces/NAME.expected`), on both engines and from all three encodings.

use cwisim_isa::{create_trace, io::read_all, Encoding, FileReader, Opcode, TraceRead};
use cwisim_tests::{check_or_bless, example_traces, machine_for, render_replay, replay_file};
use cwisim_xproc::Timing;
use std::collections::BTreeSet;

#[test]
fn examples_replay_to_their_expected_output() {
    let traces = example_traces();
    assert!(traces.len() >= 8, "expected the examples in traces/");
    for trace in &traces {
        let machine = machine_for(trace);
        let (header, image, stats) = replay_file(trace, &machine, Timing::Fast);
        let (_, image_s, stats_s) = replay_file(trace, &machine, Timing::Stepped);
        assert_eq!(image, image_s, "{}: engines differ", trace.display());
        assert_eq!(stats, stats_s, "{}: engines differ", trace.display());
        check_or_bless(
            &trace.with_extension("expected"),
            &render_replay(&header, &image, &stats),
        );
    }
}

#[test]
fn replay_is_identical_whichever_encoding_is_read() {
    let dir = std::env::temp_dir().join(format!("cwisim-traces-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for trace in example_traces() {
        let machine = machine_for(&trace);
        let (_, image, stats) = replay_file(&trace, &machine, Timing::Fast);
        let mut reader = FileReader::open(&trace).unwrap();
        let header = *reader.header();
        let instrs = read_all(&mut reader).unwrap();
        for (_, ext) in Encoding::ALL {
            let path = dir.join(trace.with_extension(ext).file_name().unwrap());
            let mut w = create_trace(&path, &header).unwrap();
            for i in &instrs {
                w.write(i).unwrap();
            }
            w.finish().unwrap();
            drop(w);
            let (_, image2, stats2) = replay_file(&path, &machine, Timing::Fast);
            assert_eq!(image, image2, "{} as .{ext}", trace.display());
            assert_eq!(stats, stats2, "{} as .{ext}", trace.display());
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn examples_use_every_opcode() {
    let mut seen = BTreeSet::new();
    for trace in example_traces() {
        let mut reader = FileReader::open(&trace).unwrap();
        for i in read_all(&mut reader).unwrap() {
            seen.insert(i.op);
        }
    }
    let missing: Vec<&Opcode> = Opcode::ALL.iter().filter(|op| !seen.contains(op)).collect();
    assert!(missing.is_empty(), "no example uses {missing:?}");
}

/// The pairs of opcodes whose order matters (`docs/ISA.md`: a mask lasts to the next Eval
/// or Refresh, a lock and a preload to the Refresh, Acc_mode toggles): each must follow
/// the other directly in some example, so that a design that got one of them wrong — an
/// `Eval0` that ignored the mask — fails a golden co-simulation, not only a random one.
#[test]
fn examples_pin_every_pair_of_opcodes_whose_order_matters() {
    use Opcode::*;
    let pairs = [
        (Dis, Eval0),
        (Dis, Eval1),
        (Dis, Dis),
        (Dis, Refresh),
        (Eval0, Eval0),
        (Eval0, Eval1),
        (Eval1, Eval0),
        (SetI, Refresh),
        (SetI, Eval2),
        (AccMode, Eval1),
        (Eval1, AccMode),
    ];
    let mut seen = BTreeSet::new();
    for trace in example_traces() {
        let mut reader = FileReader::open(&trace).unwrap();
        let instrs = read_all(&mut reader).unwrap();
        for w in instrs.windows(2) {
            seen.insert((w[0].op, w[1].op));
        }
    }
    let missing: Vec<_> = pairs.iter().filter(|p| !seen.contains(p)).collect();
    assert!(
        missing.is_empty(),
        "no example has {missing:?} in this order"
    );
}
