//! The screen scene reader on arbitrary text (seeds: the DO_FILL fixtures and the
//! embedded screen scenes, `fuzz/seed-corpus.sh`).
#![no_main]

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    cwisim_fuzz::screen_scene(&String::from_utf8_lossy(bytes));
});
