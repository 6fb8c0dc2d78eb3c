//! A texture's ancillary chunks are never inflated: a PNG whose colour profile (iCCP)
//! inflates to 96 MiB is drawn within a 64 MiB memory budget (a 0.5 MB file of such a
//! profile took 530 MB before). Its own test binary, so that the peak memory of the
//! children it waits for is its run's alone.

mod common;

use common::{png_chunk, scratch, text};
use std::path::Path;
use std::process::{Command, Output};

fn cwisim_env(dir: &Path, env: &[(&str, &str)], args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cwisim"))
        .args(args)
        .envs(env.iter().copied())
        .current_dir(dir)
        .output()
        .expect("run the cwisim binary")
}

/// The peak resident memory of the children waited for so far, bytes (Linux: KiB).
fn children_peak_bytes() -> u64 {
    // SAFETY: getrusage fills the struct it is given and reads nothing else
    let usage = unsafe {
        let mut u: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_CHILDREN, &mut u);
        u
    };
    usage.ru_maxrss as u64 * 1024
}

#[test]
fn a_texture_whose_colour_profile_inflates_to_96_mib_decodes_in_little_memory() {
    use std::io::Write;
    let dir = scratch("budgets-png-iccp");
    // a 4×4 grey PNG with an iCCP chunk of 96 MiB of zeros, compressed to about 100 KB
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..96 {
        z.write_all(&zeros).unwrap();
    }
    let profile = z.finish().unwrap();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&4u32.to_be_bytes());
    ihdr.extend_from_slice(&4u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 0, 0, 0, 0]);
    let rows: Vec<u8> = (0..4u8)
        .flat_map(|y| std::iter::once(0).chain((0..4u8).map(move |x| 10 * x + 20 * y)))
        .collect();
    let mut idat = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    idat.write_all(&rows).unwrap();
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(png_chunk(b"IHDR", &ihdr));
    let mut iccp = b"icc\0\0".to_vec();
    iccp.extend_from_slice(&profile);
    png.extend(png_chunk(b"iCCP", &iccp));
    png.extend(png_chunk(b"IDAT", &idat.finish().unwrap()));
    png.extend(png_chunk(b"IEND", b""));
    std::fs::write(dir.join("bomb.png"), &png).unwrap();
    let scene = r#"{ "kind": "world", "width": 32, "height": 32, "channels": 1,
  "camera": { "eye": [0, 0, 10], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 30 },
  "ambient": 1,
  "meshes": [ { "material": { "k_a": 1, "k_d": 0, "k_s": 0, "n": 1, "texture": { "image": "bomb.png" } },
    "vertices": [[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]],
    "uv": [[0, 0], [1, 0], [1, 1], [0, 1]], "faces": [[0, 1, 2, 3]] } ] }"#;
    std::fs::write(dir.join("s.json"), scene).unwrap();
    let out = cwisim_env(
        &dir,
        &[("CWISIM_MAX_MEMORY", "64M")],
        &["render", "s.json", "-o", "x.png", "-q"],
    );
    assert_eq!(out.status.code(), Some(0), "{:?}", text(&out));
    let peak = children_peak_bytes();
    assert!(peak < 64 << 20, "the render peaked at {} MiB", peak >> 20);
}
