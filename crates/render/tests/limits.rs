//! The limits of `docs/LIMITS.md` that no other test exceeds: each refused with a
//! message that names the limit and the value found, before anything of that size is
//! allocated.

use cwisim_isa::text::TextReader;
use cwisim_isa::{
    Instruction, Intensity, TraceHeader, TraceRead, TraceWrite, MAX_CHANNELS, MAX_LINES, MAX_WIDTH,
};
use cwisim_xproc::numeric::Numeric;
use cwisim_xproc::{EngineWriter, ImageSink, Machine, Timing};

#[test]
fn trace_headers_beyond_the_limits_are_refused_naming_limit_and_value() {
    let e = TraceHeader::new(MAX_WIDTH + 1, 1, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("65537") && e.contains("65536"), "{e}");
    let e = TraceHeader::new(1, MAX_LINES + 1, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("65537") && e.contains("65536"), "{e}");
    let e = TraceHeader::new(1, 1, MAX_CHANNELS as u8 + 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains("channels 5") && e.contains("1..=4"), "{e}");
}

#[test]
fn a_text_trace_line_beyond_the_line_limit_is_refused_at_its_line() {
    let mut text = String::from("cwisim-trace version=1 width=8 lines=1 channels=1\n");
    text.push_str(&"#".repeat(cwisim_isa::io::MAX_LINE_BYTES + 10));
    text.push('\n');
    let result = TextReader::new(text.as_bytes()).and_then(|mut r| r.next_instruction());
    let e = result.unwrap_err().to_string();
    assert!(e.contains("1048576-byte limit"), "{e}");
    assert!(e.starts_with("2:1"), "located at line 2: {e}");
}

#[test]
fn the_image_collector_refuses_an_image_beyond_its_limit() {
    // 8 values of 8 bytes a scanline; a limit of 100 bytes holds one scanline, not two
    let header = TraceHeader::new(8, 2, 1).unwrap();
    let mut sink = ImageSink::new(8, 1, 100);
    {
        let mut w = EngineWriter::with_numeric(
            &header,
            &Machine::default(),
            Timing::Fast,
            &Numeric::F64,
            &mut sink,
        )
        .unwrap();
        for i in [
            Instruction::eval1(0, 8, Intensity::grey(0.5)),
            Instruction::refresh(),
            Instruction::refresh(),
        ] {
            w.write(&i).unwrap();
        }
        w.finish().unwrap();
    }
    let e = sink.finish().unwrap_err().to_string();
    assert!(
        e.contains("exceed 100 bytes") && e.contains("scanline 1"),
        "{e}"
    );
}

#[test]
fn fixed_formats_wider_than_64_bits_are_refused() {
    let e = "fixed:I=40.30,dI=4.28,ddI=1.36"
        .parse::<Numeric>()
        .unwrap_err()
        .to_string();
    assert!(e.contains("64") && e.contains("40.30"), "{e}");
}

#[test]
fn json_nested_deeper_than_the_parser_allows_is_refused_with_a_location() {
    let deep = format!(
        "{{\"kind\": \"screen\", \"width\": 4, \"height\": 4, \"channels\": 1, \"polygons\": {}{}}}",
        "[".repeat(200),
        "]".repeat(200)
    );
    let e = cwisim_scene::parse_scene(&deep).unwrap_err().to_string();
    assert!(e.contains("recursion limit"), "{e}");
    assert!(e.starts_with("1:"), "located at line 1: {e}");
}
