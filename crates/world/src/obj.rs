//! Wavefront OBJ meshes, read with `tobj`.
//!
//! Positions (`v`), faces (`f`, any number of corners, negative indices allowed),
//! normals (`vn`, used when every corner of the file names one) and texture coordinates
//! (`vt`, likewise) are read; materials (`mtllib`, `usemtl`: the scene gives the material),
//! points and lines are ignored. All objects and groups of the file become one mesh.
//!
//! `tobj` stops at the first bad line but does not say which; this module counts the
//! lines it hands to `tobj`, so every error names the file and line.

use crate::mesh::{Face, PerCorner, Raw};
use cwisim_scene::{SceneError, SceneErrorKind};
use glam::DVec3;
use std::io::{BufRead, Cursor, Read};
use std::path::Path;

/// The largest OBJ file read (bytes).
pub const MAX_OBJ_BYTES: u64 = 512 << 20;

/// A `BufRead` that counts the lines consumed through it.
struct Counting<R> {
    inner: R,
    newlines: u64,
    partial: bool,
    at_end: bool,
}

impl<R: BufRead> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = {
            let available = self.fill_buf()?;
            let n = available.len().min(buf.len());
            buf[..n].copy_from_slice(&available[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for Counting<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        let buf = self.inner.fill_buf()?;
        if buf.is_empty() {
            self.at_end = true;
        }
        Ok(buf)
    }

    fn consume(&mut self, amt: usize) {
        if let Ok(buf) = self.inner.fill_buf() {
            let taken = &buf[..amt.min(buf.len())];
            let newlines = taken.iter().filter(|&&b| b == b'\n').count() as u64;
            self.newlines += newlines;
            if let Some(last) = taken.iter().rposition(|&b| b == b'\n') {
                self.partial = last + 1 < taken.len();
            } else if !taken.is_empty() {
                self.partial = true;
            }
        }
        self.inner.consume(amt);
    }
}

/// A fault of the OBJ file at `path`, on its line `line` when known.
pub(crate) fn error(path: &Path, line: Option<u64>, message: String) -> SceneError {
    SceneError {
        path: Some(path.to_path_buf()),
        line,
        column: line.map(|_| 1),
        field: None,
        kind: SceneErrorKind::Shape,
        message,
    }
}

/// The first `f` line naming a vertex or normal that is not defined before it.
fn first_bad_index(text: &str) -> Option<u64> {
    let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => v += 1,
            Some("vn") => vn += 1,
            Some("vt") => vt += 1,
            Some("f") => {
                for corner in words {
                    let mut parts = corner.split('/');
                    let bad = |part: Option<&str>, count: i64| match part {
                        Some(p) if !p.is_empty() => p
                            .parse::<i64>()
                            .map_or(true, |i| i == 0 || i > count || -i > count),
                        _ => false,
                    };
                    let (pv, pt, pn) = (parts.next(), parts.next(), parts.next());
                    if bad(pv, v) || bad(pt, vt) || bad(pn, vn) {
                        return Some(n as u64 + 1);
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// The line of the first `keyword` statement (`v`, `vn` or `vt`) whose values, read
/// as tobj reads them, are `found`, bit for bit: where a value tobj kept came from.
///
/// tobj's mesh holds each position, normal and texture coordinate in the order the
/// faces first use it (once for each combination of indices), not the file's order,
/// so a value is located by what it is, not by where it stands in the mesh.
fn line_of_values(text: &str, keyword: &str, found: &[f64]) -> Option<u64> {
    text.lines().enumerate().find_map(|(n, line)| {
        let mut words = line.split_whitespace();
        if words.next() != Some(keyword) {
            return None;
        }
        let mut values: Vec<f64> = Vec::with_capacity(found.len());
        for _ in 0..found.len() {
            values.push(words.next()?.parse().ok()?);
        }
        // a position's fourth number, alone, divides the three before it
        if keyword == "v" {
            if let (Some(w), None) = (words.next(), words.next()) {
                let w: f64 = w.parse().ok()?;
                values.iter_mut().for_each(|x| *x /= w);
            }
        }
        let same = values
            .iter()
            .zip(found)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        same.then_some(n as u64 + 1)
    })
}

/// Reads an OBJ file into positions, faces and (when complete) per-corner normals.
pub(crate) fn read(path: &Path) -> Result<Raw, SceneError> {
    let io = |e: std::io::Error| SceneError {
        kind: SceneErrorKind::Io,
        ..error(path, None, format!("cannot read the OBJ file: {e}"))
    };
    // what is not a regular file is refused before a byte is read: a FIFO would block
    // forever, a device such as /dev/zero read up to the size limit
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(SceneError {
            kind: SceneErrorKind::Io,
            ..error(
                path,
                None,
                "not a regular file (an OBJ file is expected)".into(),
            )
        });
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    file.take(MAX_OBJ_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_OBJ_BYTES {
        return Err(SceneError {
            kind: SceneErrorKind::Limit,
            ..error(
                path,
                None,
                format!("the OBJ file is larger than {MAX_OBJ_BYTES} bytes"),
            )
        });
    }
    let mut reader = Counting {
        inner: Cursor::new(&bytes),
        newlines: 0,
        partial: false,
        at_end: false,
    };
    let options = tobj::LoadOptions {
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let loaded = tobj::load_obj_buf(&mut reader, &options, |_| {
        Ok((Vec::new(), Default::default()))
    });
    let models = match loaded {
        Ok((models, _materials)) => models,
        Err(e) => {
            let counted = Some(reader.newlines + u64::from(reader.partial));
            let out_of_bounds = matches!(
                e,
                tobj::LoadError::FaceVertexOutOfBounds
                    | tobj::LoadError::FaceTexCoordOutOfBounds
                    | tobj::LoadError::FaceNormalOutOfBounds
            );
            let line = if reader.at_end && out_of_bounds {
                // tobj checks indices only once the whole file is read: find the face.
                // Any other fault is on the line it stopped at, even a last line that,
                // lacking its newline, took it to the end of the file.
                first_bad_index(&String::from_utf8_lossy(&bytes)).or(counted)
            } else {
                counted
            };
            let what = match e {
                tobj::LoadError::PositionParseError => {
                    "expected a position `v x y z` with 3 (or 4) numbers".into()
                }
                tobj::LoadError::NormalParseError => {
                    "expected a normal `vn x y z` with 3 numbers".into()
                }
                tobj::LoadError::TexcoordParseError => {
                    "expected texture coordinates `vt u v` with 2 (or 3) numbers".into()
                }
                tobj::LoadError::FaceTexCoordOutOfBounds => {
                    "a face names texture coordinates that are not defined before them".into()
                }
                tobj::LoadError::FaceParseError | tobj::LoadError::InvalidPolygon => {
                    "expected a face `f i j k …` of vertex indices (v, v/t, v//n or v/t/n)".into()
                }
                tobj::LoadError::FaceVertexOutOfBounds => {
                    "a face names a vertex that is not defined before it".into()
                }
                tobj::LoadError::FaceNormalOutOfBounds => {
                    "a face names a normal that is not defined before it".into()
                }
                other => format!("not a valid OBJ file ({other})"),
            };
            return Err(error(path, line, what));
        }
    };
    // the `v`, `vn` and `vt` lines, to locate a value refused
    let text = String::from_utf8_lossy(&bytes);
    let line_of = |keyword: &str, found: &[f64]| line_of_values(&text, keyword, found);
    let mut positions = Vec::new();
    let mut faces: Vec<Face> = Vec::new();
    let mut all_have_normals = true;
    let mut all_have_uv = true;
    for model in &models {
        let m = &model.mesh;
        let base = positions.len() as u32;
        for p in m.positions.chunks_exact(3) {
            let v = DVec3::new(p[0], p[1], p[2]);
            if !v.is_finite() {
                return Err(SceneError {
                    kind: SceneErrorKind::NonFinite,
                    ..error(
                        path,
                        line_of("v", p),
                        format!("expected finite coordinates, found {v}"),
                    )
                });
            }
            positions.push(v);
        }
        let mesh_normals: Vec<DVec3> = m
            .normals
            .chunks_exact(3)
            .map(|n| DVec3::new(n[0], n[1], n[2]))
            .collect();
        if let Some(bad) = mesh_normals.iter().position(|n| !n.is_finite()) {
            return Err(SceneError {
                kind: SceneErrorKind::NonFinite,
                ..error(
                    path,
                    line_of("vn", &m.normals[3 * bad..3 * bad + 3]),
                    "expected a finite normal".into(),
                )
            });
        }
        let arities: Vec<u32> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.clone()
        };
        let has_normals = m.normal_indices.len() == m.indices.len() && !mesh_normals.is_empty();
        all_have_normals &= has_normals;
        let has_uv = m.texcoord_indices.len() == m.indices.len() && !m.texcoords.is_empty();
        all_have_uv &= has_uv;
        if has_uv {
            if let Some(bad) = m.texcoords.iter().position(|x| !x.is_finite()) {
                return Err(SceneError {
                    kind: SceneErrorKind::NonFinite,
                    ..error(
                        path,
                        line_of("vt", &m.texcoords[bad / 2 * 2..bad / 2 * 2 + 2]),
                        "expected finite texture coordinates".into(),
                    )
                });
            }
            // the bound inline `uv` has: beyond it a texel index loses its meaning
            let bound = crate::scene::MAX_WORLD_COORDINATE;
            if let Some(bad) = m.texcoords.iter().position(|x| x.abs() > bound) {
                return Err(SceneError {
                    kind: SceneErrorKind::Limit,
                    ..error(
                        path,
                        line_of("vt", &m.texcoords[bad / 2 * 2..bad / 2 * 2 + 2]),
                        format!(
                            "expected texture coordinates within ±1e9, found {:e}",
                            m.texcoords[bad]
                        ),
                    )
                });
            }
        }
        let mut at = 0usize;
        for arity in arities {
            let range = at..at + arity as usize;
            let mut face = Face {
                corners: m.indices[range.clone()].iter().map(|i| base + i).collect(),
                normals: PerCorner::new(),
                uv: PerCorner::new(),
            };
            if has_uv {
                face.uv = m.texcoord_indices[range.clone()]
                    .iter()
                    .map(|&t| {
                        let t = t as usize;
                        [m.texcoords[2 * t], m.texcoords[2 * t + 1]]
                    })
                    .collect();
            }
            if has_normals {
                face.normals = m.normal_indices[range]
                    .iter()
                    .map(|&n| mesh_normals[n as usize])
                    .collect();
            }
            faces.push(face);
            at += arity as usize;
        }
    }
    // each face's `f` line (tobj ignores one of fewer than 3 corners: a point or a
    // line), when every such line made one face as tobj read them
    let f_lines: Vec<u64> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| {
            let mut words = l.split_whitespace();
            words.next() == Some("f") && words.count() >= 3
        })
        .map(|(n, _)| n as u64 + 1)
        .collect();
    let face_lines = (f_lines.len() == faces.len()).then_some(f_lines);
    // normals and texture coordinates are the mesh's when every face has them
    for face in &mut faces {
        if !all_have_normals {
            face.normals.clear();
        }
        if !all_have_uv {
            face.uv.clear();
        }
    }
    Ok(Raw {
        face_lines,
        positions,
        normals_given: all_have_normals && !faces.is_empty(),
        faces,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("cwisim-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[cfg(unix)]
    #[test]
    fn what_is_not_a_regular_file_is_refused_before_it_is_read() {
        // a FIFO with no writer would block a read forever; /dev/zero would be read to
        // the size limit
        let dir = std::env::temp_dir().join(format!("cwisim-obj-fifo-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("mesh.obj");
        let _ = std::fs::remove_file(&fifo);
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        for path in [fifo.as_path(), Path::new("/dev/zero")] {
            let e = read(path).unwrap_err();
            assert_eq!(e.kind, SceneErrorKind::Io, "{e}");
            assert!(e.message.contains("not a regular file"), "{e}");
            assert_eq!(e.path.as_deref(), Some(path));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reads_quads_triangles_negative_indices_and_normals() {
        let p = write(
            "ok.obj",
            "# a square and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\n\
             f 1//1 2//1 3//1 4//1\nf -4//1 -3//1 -1//1\n",
        );
        let raw = read(&p).unwrap();
        assert_eq!(raw.positions.len(), 4);
        let faces: Vec<&[u32]> = raw.faces.iter().map(|f| &f.corners[..]).collect();
        assert_eq!(faces, [&[0, 1, 2, 3][..], &[0, 1, 3]]);
        assert!(raw.normals_given);
        assert_eq!(raw.faces[1].normals[..], [DVec3::Z; 3]);
    }

    #[test]
    fn errors_name_the_line() {
        let p = write("bad.obj", "v 0 0 0\nv 1 0 0\nv 1 x 0\nf 1 2 3\n");
        let e = read(&p).unwrap_err();
        assert_eq!(e.line, Some(3), "{e}");
        assert!(
            e.to_string().contains("bad.obj:3:1: expected a position"),
            "{e}"
        );
        let p = write("oob.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 2 9\n");
        let e = read(&p).unwrap_err();
        assert_eq!(e.line, Some(5), "{e}");
        let p = write(
            "nan.obj",
            "v 0 0 0\nvn 0 0 1\nv NaN 0 0\nv 1 1 0\nf 1 2 3\n",
        );
        let e = read(&p).unwrap_err();
        assert_eq!(
            (e.line, e.kind),
            (Some(3), SceneErrorKind::NonFinite),
            "{e}"
        );
    }

    /// Found by `mutated_obj_files`: a refused value was located by its place in tobj's
    /// mesh, which is the order faces first use a value (once for each combination of
    /// indices), not the file's. A vertex used first, or with several normals, was put on
    /// another line or on none.
    #[test]
    fn a_refused_value_is_located_on_its_own_line() {
        for (k, (obj, line)) in [
            // the fourth vertex, used first: it was put on line 1
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 1\nf 4 2 3\n", 4),
            // a vertex with two normals is two of the mesh's positions: no line was found
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e999 0 1\nvn 0 0 1\nvn 0 1 0\n\
                 f 1//1 2//1 3//1\nf 1//2 2//2 3//2\nf 1//1 2//1 4//1\n",
                4,
            ),
            // scaled by its fourth number to a value that is not finite
            ("v 0 0 0\nv 1e300 0 1 1e-300\nv 0 1 0\nf 3 2 1\n", 2),
            // a normal and texture coordinates out of order
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn nan 0 1\nf 1//2 2//1 3//1\n",
                5,
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 0 2e9\nf 1/2 2/1 3/1\n",
                5,
            ),
        ]
        .into_iter()
        .enumerate()
        {
            let e = read(&write(&format!("order{k}.obj"), obj)).unwrap_err();
            assert_eq!(e.line, Some(line), "{k}: {e}");
        }
    }
}
