//! Writing a triangle mesh as Wavefront OBJ: `v x y z r g b` (the common
//! vertex-colour extension, colours in [0, 1]), `vn`, `f a//a b//b c//c`
//! (1-based). What `input::load_obj` reads back; used to export a procedural
//! rock (§6.1.4) for `spt build` (dissertation Fig. 10.11).

use std::io::Write;
use std::path::Path;

use crate::error::{Error, Result};
use crate::points::TriangleMesh;

/// Writes `mesh` to `path` as OBJ (see the module documentation).
///
/// Errors (one line, naming the file): the file cannot be written.
pub fn write_obj(mesh: &TriangleMesh, path: &Path) -> Result<()> {
    let fail = |e: std::io::Error| Error::output(path, e);
    let file = std::fs::File::create(path).map_err(fail)?;
    let mut out = std::io::BufWriter::new(file);
    for (i, p) in mesh.positions.iter().enumerate() {
        write!(out, "v {} {} {}", p.x, p.y, p.z).map_err(fail)?;
        if let Some(c) = mesh.colors.as_ref().and_then(|c| c.get(i)) {
            let [r, g, b] = c.map(|v| f32::from(v) / 255.0);
            write!(out, " {r} {g} {b}").map_err(fail)?;
        }
        writeln!(out).map_err(fail)?;
    }
    let normals = mesh.normals.as_ref().filter(|n| n.len() == mesh.positions.len());
    for n in normals.into_iter().flatten() {
        writeln!(out, "vn {} {} {}", n.x, n.y, n.z).map_err(fail)?;
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        match normals {
            Some(_) => writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}"),
            None => writeln!(out, "f {a} {b} {c}"),
        }
        .map_err(fail)?;
    }
    out.flush().map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::build::input::load_obj;
    use crate::points::build::rocks::{generate_rock, RockParams};

    /// The text's rock of Fig. 10.11: 8 extreme hull points (12 faces) and 7
    /// subdivisions give 12 · 4⁷ = 196 608 triangles; the OBJ reads back
    /// as the same mesh (positions to the last bit, colours exactly).
    #[test]
    fn the_figure_rock_has_196_608_triangles_and_round_trips() {
        let params = RockParams {
            points: 8,
            subdivisions: 7,
            ..RockParams::default()
        };
        let mesh = generate_rock(&params).unwrap();
        assert_eq!(mesh.triangles.len(), 196_608);
        // A closed genus-0 triangle mesh: V − E + F = 2 with E = 3F/2.
        assert_eq!(mesh.positions.len(), 196_608 / 2 + 2);
        let path = std::env::temp_dir().join(format!("alpenglow-rock-{}.obj", std::process::id()));
        write_obj(&mesh, &path).unwrap();
        let back = load_obj(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        // tobj renumbers the vertices in order of first use: compare corners.
        assert_eq!(back.triangles.len(), mesh.triangles.len());
        let (back_colors, colors) = (back.colors.as_ref().unwrap(), mesh.colors.as_ref().unwrap());
        let mut moved = 0.0f32;
        for (b, m) in back.triangles.iter().zip(&mesh.triangles) {
            for k in 0..3 {
                let (bi, mi) = (b[k] as usize, m[k] as usize);
                moved = moved.max((back.positions[bi] - mesh.positions[mi]).abs().max_element());
                assert_eq!(back_colors[bi], colors[mi]);
            }
        }
        assert!(moved <= 1e-6, "positions moved by {moved}");
        let bad = std::env::temp_dir().join("no-such-dir-alpenglow").join("rock.obj");
        let line = write_obj(&mesh, &bad).unwrap_err().to_string();
        assert!(line.contains("rock.obj") && !line.contains('\n'), "{line}");
    }
}
