//! Lossless round trips between the three encodings, on random traces (proptest).

use cwisim_isa::io::read_all;
use cwisim_isa::{Encoding, Instruction, Opcode, TraceHeader};
use proptest::prelude::*;

fn any_value() -> impl Strategy<Value = f64> {
    prop_oneof![
        // every finite bit pattern: subnormals, -0.0, huge and tiny exponents
        any::<u64>()
            .prop_map(f64::from_bits)
            .prop_filter("finite", |v| v.is_finite()),
        -4.0f64..4.0,
        Just(0.0),
        Just(-0.0),
    ]
}

fn trace() -> impl Strategy<Value = (TraceHeader, Vec<Instruction>)> {
    (
        1u32..300,
        1u32..8,
        prop_oneof![Just(1u8), Just(3u8), 1u8..=4],
    )
        .prop_flat_map(|(width, lines, channels)| {
            let header = TraceHeader::new(width, lines, channels).unwrap();
            let instr = (
                0..Opcode::COUNT,
                0..width,
                0u32..=width,
                proptest::collection::vec(any_value(), 3 * usize::from(channels)),
            )
                .prop_map(move |(k, x, n, vals)| {
                    let c = usize::from(channels);
                    Instruction::from_operands(
                        Opcode::ALL[k],
                        x,
                        n.min(width - x),
                        n.max(1),
                        &vals,
                        c,
                    )
                });
            (Just(header), proptest::collection::vec(instr, 0..60))
        })
}

fn encode(enc: Encoding, header: &TraceHeader, instrs: &[Instruction]) -> Vec<u8> {
    let mut buf = Vec::new();
    {
        let mut w = enc.writer(&mut buf, header).unwrap();
        for i in instrs {
            w.write(i).unwrap();
        }
        w.finish().unwrap();
    }
    buf
}

fn decode(enc: Encoding, bytes: &[u8]) -> (TraceHeader, Vec<Instruction>) {
    let mut r = enc.reader(bytes).unwrap();
    let v = read_all(&mut *r).unwrap();
    (*r.header(), v)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn every_encoding_is_lossless((header, instrs) in trace()) {
        for (enc, _) in Encoding::ALL {
            let bytes = encode(enc, &header, &instrs);
            let (h, back) = decode(enc, &bytes);
            prop_assert_eq!(h, header);
            prop_assert_eq!(&back, &instrs);
        }
    }

    #[test]
    fn text_to_jsonl_to_binary_to_text_is_byte_identical((header, instrs) in trace()) {
        let text = encode(Encoding::Text, &header, &instrs);
        let (h1, v1) = decode(Encoding::Text, &text);
        let jsonl = encode(Encoding::JsonLines, &h1, &v1);
        let (h2, v2) = decode(Encoding::JsonLines, &jsonl);
        let bin = encode(Encoding::Binary, &h2, &v2);
        let (h3, v3) = decode(Encoding::Binary, &bin);
        let text_again = encode(Encoding::Text, &h3, &v3);
        prop_assert_eq!(text, text_again);
    }
}

/// A note's text: one to three lines of printable text (spaces, `#` and empty lines
/// included), or none.
fn any_note() -> impl Strategy<Value = Option<String>> {
    proptest::option::weighted(
        0.3,
        proptest::collection::vec("[ -~]{0,12}", 1..4).prop_map(|lines| lines.join("\n")),
    )
}

/// A trace with a note before some of its instructions.
fn noted_trace() -> impl Strategy<Value = (TraceHeader, Vec<(Option<String>, Instruction)>)> {
    trace().prop_flat_map(|(header, instrs)| {
        let n = instrs.len();
        (
            Just(header),
            Just(instrs),
            proptest::collection::vec(any_note(), n),
        )
            .prop_map(|(h, instrs, notes)| (h, notes.into_iter().zip(instrs).collect()))
    })
}

fn encode_noted(
    enc: Encoding,
    header: &TraceHeader,
    stream: &[(Option<String>, Instruction)],
) -> Vec<u8> {
    let mut buf = Vec::new();
    {
        let mut w = enc.writer(&mut buf, header).unwrap();
        for (note, i) in stream {
            if let Some(n) = note {
                w.comment(n).unwrap();
            }
            w.write(i).unwrap();
        }
        w.finish().unwrap();
    }
    buf
}

/// Each instruction with the serial and text of its note.
type Read = Vec<(Instruction, Option<(u64, String)>)>;

fn decode_noted(enc: Encoding, bytes: &[u8]) -> Read {
    let mut r = enc.reader(bytes).unwrap();
    let mut out = Vec::new();
    while let Some(i) = r.next_instruction().unwrap() {
        out.push((i, r.note().map(|n| (n.serial, n.text.to_string()))));
    }
    out
}

/// The notes of the rule (`cwisim_isa::note`), computed apart: a note covers its
/// instruction and the ones after it up to the next note or `Refresh`, a `Refresh` only
/// when attached to it.
fn expected(stream: &[(Option<String>, Instruction)]) -> Read {
    let (mut serial, mut in_force) = (0u64, None::<(u64, String)>);
    let mut out = Vec::new();
    for (note, i) in stream {
        let refresh = i.op == Opcode::Refresh;
        let text = note.as_deref().map(cwisim_isa::note::normalized);
        let covered = match text {
            Some(t) => {
                let n = (serial, t);
                serial += 1;
                in_force = (!refresh).then(|| n.clone());
                Some(n)
            }
            None if refresh => {
                in_force = None;
                None
            }
            None => in_force.clone(),
        };
        out.push((i.clone(), covered));
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// `.cwt` and `.jsonl` keep every note on the instructions it covers; `.cwb` drops
    /// them; the instructions are the same in all three, with notes or without.
    #[test]
    fn notes_survive_the_encodings_that_carry_them((header, stream) in noted_trace()) {
        let want = expected(&stream);
        let plain: Vec<Instruction> = stream.iter().map(|(_, i)| i.clone()).collect();
        for (enc, _) in Encoding::ALL {
            let got = decode_noted(enc, &encode_noted(enc, &header, &stream));
            let instrs: Vec<Instruction> = got.iter().map(|(i, _)| i.clone()).collect();
            prop_assert_eq!(&instrs, &plain);
            if enc == Encoding::Binary {
                prop_assert!(got.iter().all(|(_, n)| n.is_none()));
            } else {
                prop_assert_eq!(&got, &want, "{:?}", enc);
            }
        }
    }

    /// Copying a trace as `cwisim convert` does (each note once, before the first
    /// instruction it covers): `.cwt` → `.jsonl` → `.cwt` gives the same bytes.
    #[test]
    fn notes_convert_back_and_forth((header, stream) in noted_trace()) {
        let text = encode_noted(Encoding::Text, &header, &stream);
        let jsonl = copy(&text, Encoding::Text, Encoding::JsonLines);
        let back = copy(&jsonl, Encoding::JsonLines, Encoding::Text);
        prop_assert_eq!(String::from_utf8(back).unwrap(), String::from_utf8(text).unwrap());
    }
}

/// `bytes` of encoding `from` re-encoded as `to`, notes and all.
fn copy(bytes: &[u8], from: Encoding, to: Encoding) -> Vec<u8> {
    let mut r = from.reader(bytes).unwrap();
    let mut out = Vec::new();
    {
        let mut w = to.writer(&mut out, r.header()).unwrap();
        let mut last = None;
        while let Some(i) = r.next_instruction().unwrap() {
            let note = r.note();
            if let Some(n) = note.filter(|n| last != Some(n.serial)) {
                w.comment(n.text).unwrap();
            }
            last = note.map(|n| n.serial);
            w.write(&i).unwrap();
        }
        w.finish().unwrap();
    }
    out
}
