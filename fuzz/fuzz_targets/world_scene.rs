//! The scene reader of the command line (screen or world, with revolutions, Bézier
//! patches and OBJ references) on arbitrary text (seeds: the embedded scenes,
//! `fuzz/seed-corpus.sh`). OBJ files are looked for in an empty temporary directory.
#![no_main]

use std::sync::OnceLock;

fn base() -> &'static std::path::Path {
    static BASE: OnceLock<std::path::PathBuf> = OnceLock::new();
    BASE.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("cwisim-fuzz-world-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        dir
    })
}

libfuzzer_sys::fuzz_target!(|bytes: &[u8]| {
    cwisim_fuzz::any_scene(&String::from_utf8_lossy(bytes), base());
});
