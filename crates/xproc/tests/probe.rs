//! The probe of the cycle-stepped engine: what it reports agrees with the replay.

use cwisim_isa::{text::TextReader, Instruction, Opcode};
use cwisim_xproc::{replay_probed, ImageSink, Machine, Probe, ProcessorState};

#[derive(Default)]
struct Log {
    issues: Vec<(u64, u64, u64)>, // cycle, index, line
    enters: Vec<(u64, u64)>,      // cycle, index
    visits: Vec<(u64, usize, u64, Opcode, ProcessorState, ProcessorState)>,
    ready: Vec<(u64, u64)>,
}

impl Probe for Log {
    fn watches(&self, p: usize) -> bool {
        p == 2 || p == 5
    }
    fn issue(&mut self, cycle: u64, index: u64, line: u64, _i: &Instruction) {
        self.issues.push((cycle, index, line));
    }
    fn enter(&mut self, cycle: u64, index: u64) {
        self.enters.push((cycle, index));
    }
    fn visit(
        &mut self,
        cycle: u64,
        p: usize,
        index: u64,
        _line: u64,
        i: &Instruction,
        _a: bool,
        b: &ProcessorState,
        a: &ProcessorState,
    ) {
        self.visits
            .push((cycle, p, index, i.op, b.clone(), a.clone()));
    }
    fn line_ready(&mut self, cycle: u64, line: u64) {
        self.ready.push((cycle, line));
    }
}

const TRACE: &str = "cwisim-trace version=1 width=8 lines=2 channels=1
SetI 5 0.5
Eval2 0 8 0.0 0.25
Dis 2 1
Eval1 0 8 1.0
Refresh
Acc_mode
Eval1 2 4 -0.25
Refresh
";

#[test]
fn the_probe_sees_what_the_array_does() {
    let mut reader = TextReader::new(TRACE.as_bytes()).unwrap();
    let mut sink = ImageSink::new(8, 1, 1 << 20);
    let mut log = Log::default();
    let stats =
        replay_probed::<f64>(&mut reader, &Machine::default(), &mut log, &mut sink).unwrap();
    let image = sink.finish().unwrap();
    let n = 8u64;
    // every instruction is issued once and enters once, in order, after its issue
    assert_eq!(
        log.issues.iter().map(|i| i.1).collect::<Vec<_>>(),
        (0..n).collect::<Vec<_>>()
    );
    assert_eq!(
        log.enters.iter().map(|e| e.1).collect::<Vec<_>>(),
        (0..n).collect::<Vec<_>>()
    );
    for (is, en) in log.issues.iter().zip(&log.enters) {
        assert!(en.0 > is.0);
    }
    // the first issue of each line and its readiness match the statistics
    for l in &stats.lines {
        let first = log.issues.iter().find(|i| i.2 == l.line).unwrap();
        assert_eq!(first.0, l.first_issue);
        assert!(
            log.ready.contains(&(l.ready, l.line)),
            "{:?} vs {:?}",
            log.ready,
            (l.ready, l.line)
        );
    }
    // each watched processor sees every token, one hop after processor 0 per position
    for p in [2usize, 5] {
        let v: Vec<_> = log.visits.iter().filter(|v| v.1 == p).collect();
        assert_eq!(v.len() as u64, n);
        for (k, visit) in v.iter().enumerate() {
            let entered = log.enters[k].0;
            assert_eq!(visit.0, entered + p as u64, "hop_cycles = 1");
            if k + 1 < v.len() {
                assert_eq!(
                    visit.5,
                    v[k + 1].4,
                    "after of one visit is before of the next"
                );
            }
        }
        // what each Refresh found in the accumulator is what the array output
        let refreshes: Vec<_> = v.iter().filter(|v| v.3 == Opcode::Refresh).collect();
        for (line, r) in refreshes.iter().enumerate() {
            assert_eq!(r.4.acc[0], image.data[line * 8 + p]);
        }
    }
    // processor 2: masked by Dis for the Eval1, so only the ramp (0.5) on line 0;
    // processor 5: the preload restarts the ramp at 0.5, then Eval1 adds 1.0
    assert_eq!(image.data[2], 0.5);
    assert_eq!(image.data[5], 1.5);
    // line 1: negative accumulation on after Acc_mode
    assert_eq!(image.data[8 + 2], -0.25);
    let dis_visit = log
        .visits
        .iter()
        .find(|v| v.1 == 2 && v.3 == Opcode::Dis)
        .unwrap();
    assert!(!dis_visit.4.masked && dis_visit.5.masked);
}
