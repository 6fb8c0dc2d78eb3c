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
