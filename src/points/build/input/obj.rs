//! Wavefront OBJ input (see the parent module's documentation): `tobj`
//! parses, after a pre-pass over the text that drops line (`l`) statements,
//! which tobj would otherwise read like faces (an OBJ of only `l 1 2 3`
//! became a triangle), and rejects non-finite `v` coordinates with their
//! line number, used by a face or not.

use std::borrow::Cow;
use std::path::Path;

use glam::Vec3;

use super::unit_or_zero;
use crate::error::{Error, Result};
use crate::points::TriangleMesh;

/// `text` without its line statements (blanked, so line numbers stay), or
/// a one-line message naming the first vertex with a non-finite coordinate.
fn faces_only(text: &str) -> std::result::Result<Cow<'_, str>, String> {
    let mut has_lines = false;
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("l") => has_lines = true,
            Some("v") => {
                // Only values tobj would accept: unparsable ones are its errors.
                let xyz: Vec<f32> = words.take(3).filter_map(|w| w.parse().ok()).collect();
                if xyz.iter().any(|v| !v.is_finite()) {
                    let shown: Vec<String> = xyz.iter().map(f32::to_string).collect();
                    return Err(format!(
                        "line {}: vertex has a non-finite coordinate ({})",
                        n + 1,
                        shown.join(", ")
                    ));
                }
            }
            _ => {}
        }
    }
    if !has_lines {
        return Ok(Cow::Borrowed(text));
    }
    let mut out = String::with_capacity(text.len());
    for line in text.split_inclusive('\n') {
        if line.split_whitespace().next() == Some("l") {
            out.push_str(if line.ends_with('\n') { "\n" } else { "" });
        } else {
            out.push_str(line);
        }
    }
    Ok(Cow::Owned(out))
}

/// Parses OBJ file bytes; `path` names the file in errors.
pub(super) fn read_obj(bytes: &[u8], path: &Path) -> Result<TriangleMesh> {
    let bad = |message: String| Error::input(path, message);
    let text = std::str::from_utf8(bytes).map_err(|_| bad("not UTF-8 text".to_string()))?;
    let text = faces_only(text).map_err(bad)?;
    let mut reader = text.as_bytes();
    // Triangulated, single index, points and lines dropped.
    let options = tobj::GPU_LOAD_OPTIONS;
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // Materials are never loaded (see the module documentation).
        tobj::load_obj_buf(&mut reader, &options, |_| Err(tobj::LoadError::GenericFailure))
    }));
    let models = match parsed {
        Ok(Ok((models, _materials))) => models,
        Ok(Err(e)) => return Err(bad(format!("invalid OBJ: {e}"))),
        Err(_) => return Err(bad("invalid OBJ: malformed face indices".to_string())),
    };

    let mut mesh = TriangleMesh::default();
    let total: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    if total > 0 && u32::try_from(total - 1).is_err() {
        return Err(bad(format!(
            "OBJ file has {total} vertices, more than 32-bit indices can address"
        )));
    }
    let mut all_normals = true;
    let mut all_colors = true;
    let mut normals = Vec::new();
    let mut colors = Vec::new();
    let mut color_scale = 255.0f32;
    for model in &models {
        let m = &model.mesh;
        let count = m.positions.len() / 3;
        let offset = mesh.positions.len() as u32; // < total, checked above
        mesh.positions
            .extend(m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
        if m.normals.len() == m.positions.len() {
            normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| unit_or_zero(Vec3::new(n[0], n[1], n[2]))),
            );
        } else {
            all_normals = false;
        }
        if m.vertex_color.len() == m.positions.len() {
            colors.extend(m.vertex_color.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
            if m.vertex_color.iter().any(|&c| c > 1.0) {
                // Some writers store 0–255 rather than 0–1.
                color_scale = 1.0;
            }
        } else {
            all_colors = false;
        }
        for t in m.indices.chunks_exact(3) {
            if let Some(&i) = t.iter().find(|&&i| i as usize >= count) {
                return Err(bad(format!("OBJ face refers to vertex {i} of {count}")));
            }
            mesh.triangles.push([t[0] + offset, t[1] + offset, t[2] + offset]);
        }
    }
    if let Some(p) = mesh.positions.iter().find(|p| !p.is_finite()) {
        return Err(bad(format!(
            "OBJ vertex has a non-finite coordinate ({}, {}, {})",
            p.x, p.y, p.z
        )));
    }
    if mesh.triangles.is_empty() {
        return Err(bad("OBJ file has no faces".to_string()));
    }
    if all_normals {
        mesh.normals = Some(normals);
    }
    if all_colors {
        let byte = |c: f32| (c * color_scale).clamp(0.0, 255.0).round() as u8; // NaN → 0
        mesh.colors = Some(colors.iter().map(|c| c.map(byte)).collect());
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::super::load_points_file;
    use super::super::tests::{data, mesh, Scratch};
    use super::*;

    fn obj_err(text: &[u8]) -> String {
        let message = read_obj(text, Path::new("t.obj")).unwrap_err().to_string();
        assert!(message.starts_with("t.obj: ") && !message.contains('\n'), "{message:?}");
        message
    }

    #[test]
    fn lines_are_not_faces() {
        // Only lines: no faces (tobj alone made `l 1 2 3` a triangle).
        let only_lines = "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n";
        assert_eq!(obj_err(only_lines.as_bytes()), "t.obj: OBJ file has no faces");
        assert_eq!(obj_err(b"v 0 0 0\nv 1 0 0\nl 1 2"), "t.obj: OBJ file has no faces");
        // Lines beside faces are dropped, the faces kept.
        let mixed = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nl 1 2 3 4\nf 1 2 3\n  l 2 4\n";
        let m = read_obj(mixed.as_bytes(), Path::new("t.obj")).unwrap();
        assert_eq!(m.triangles.len(), 1);
        assert_eq!(m.positions.len(), 3);
    }

    #[test]
    fn obj_values_and_indices_are_checked() {
        // A non-finite vertex is an error even if no face uses it.
        let message = obj_err(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 0\nf 1 2 3\n");
        assert!(
            message.contains("line 4: vertex has a non-finite coordinate"),
            "{message}"
        );
        let message = obj_err(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1e39 0 0\nf 1 2 4\n");
        assert!(message.contains("line 4: vertex has a non-finite"), "{message}");
        // Out-of-range indices, either sign.
        for face in ["f 1 2 4", "f 1 2 -4", "f 0 1 2", "f 1 2 99999999999"] {
            let message = obj_err(format!("v 0 0 0\nv 1 0 0\nv 0 1 0\n{face}\n").as_bytes());
            assert!(message.contains("invalid OBJ"), "{face}: {message}");
        }
        assert_eq!(obj_err(b"v 0 0 \xff\n"), "t.obj: not UTF-8 text");
    }

    #[test]
    fn obj_teapot_loads() {
        let m = mesh(load_points_file(&data("models/teapot.obj")).unwrap());
        assert_eq!(m.positions.len(), 3644);
        assert_eq!(m.triangles.len(), 6320);
        assert_eq!((m.normals, m.colors), (None, None));
    }

    #[test]
    fn obj_stanford_bunny_loads() {
        let path = data("models/stanford-bunny.obj");
        let m = mesh(load_points_file(&path).unwrap());
        assert_eq!(m.triangles.len(), 69_451);
        // The file has 35,947 `v` lines, but 1,113 of them are used by no
        // face; tobj's single index keeps only the 34,834 used ones.
        let text = std::fs::read_to_string(&path).unwrap();
        let v_lines = text.lines().filter(|l| l.starts_with("v ")).count();
        let mut used: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("f "))
            .flat_map(|l| l.split_whitespace().skip(1))
            .collect();
        used.sort_unstable();
        used.dedup();
        assert_eq!((v_lines, used.len()), (35_947, 34_834));
        assert_eq!(m.positions.len(), 34_834);
        let n = m.positions.len() as u32;
        assert!(m.triangles.iter().flatten().all(|&i| i < n));
    }

    #[test]
    fn obj_colors_normals_polygons_and_groups() {
        let text = "o a\nv 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 1 1 1\nvn 0 0 2\n\
                    f 1//1 2//1 3//1 4//1\no b\nf 1//1 3//1 4//1\nl 1 2\n";
        let m = read_obj(text.as_bytes(), Path::new("t.obj")).unwrap();
        // Two objects, each with its own single-index vertices.
        assert_eq!(m.triangles.len(), 3);
        assert_eq!(m.positions.len(), 4 + 3);
        assert_eq!(m.normals, Some(vec![Vec3::Z; 7]));
        let colors = m.colors.unwrap();
        assert_eq!(&colors[..4], &[[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]]);
        // Normals on only some corners: none at all.
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2 3\n";
        let m = read_obj(text.as_bytes(), Path::new("t.obj")).unwrap();
        assert_eq!(m.normals, None);
    }

    #[test]
    fn truncated_and_malformed_obj_are_errors() {
        // Cut in the middle of the vertex list, inside a number.
        let teapot = std::fs::read(data("models/teapot.obj")).unwrap();
        let cut = teapot.len() / 3;
        let line_start = teapot[..cut].iter().rposition(|&b| b == b'\n').unwrap() + 1;
        let mut bytes = teapot[..line_start].to_vec();
        bytes.extend_from_slice(b"v -2.9");
        let file = Scratch::new("truncated.obj", &bytes);
        let message = load_points_file(&file.0).unwrap_err().to_string();
        assert!(
            message.starts_with(&format!("{}: invalid OBJ", file.0.display())),
            "{message}"
        );
        // Cut at a line break before the faces: no faces.
        let file = Scratch::new("vertices-only.obj", &teapot[..line_start]);
        let message = load_points_file(&file.0).unwrap_err().to_string();
        assert!(
            message.ends_with("vertices-only.obj: OBJ file has no faces"),
            "{message}"
        );

        let cases: [(&str, &str); 5] = [
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                "invalid OBJ: face vertex index out of bounds",
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "invalid OBJ: face parse error"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nv nan 0 0\nf 1 2 4\n",
                "line 4: vertex has a non-finite coordinate (NaN, 0, 0)",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/-99999999 2/1 3/1\n",
                "invalid OBJ",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//-99999999 2//1 3//1\n",
                "invalid OBJ",
            ),
        ];
        for (text, expected) in cases {
            let message = read_obj(text.as_bytes(), Path::new("t.obj")).unwrap_err().to_string();
            assert!(
                message.starts_with("t.obj: ") && message.contains(expected),
                "{message:?}"
            );
        }
    }
}
