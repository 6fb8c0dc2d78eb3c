//! The .cwt trace reader on arbitrary bytes (seeds: the golden traces, `fuzz/seed-corpus.sh`).
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    cwisim_fuzz::trace(cwisim_isa::Encoding::Text, bytes);
});
