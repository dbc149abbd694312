//! Point-based rendering inputs (dissertation §10.1; `ALGORITHMS.md` §7): the
//! sequential point tree is built from surface samples, which come either from
//! a triangle mesh (sampled later, see `sampling`) or directly from scanned
//! points. This module reads both kinds from PLY and OBJ files.
//!
//! * [`load_points_file`] dispatches on the extension (`.ply`, `.obj`, any
//!   case) and returns a [`PointInput`].
//! * PLY (ASCII, binary little- and big-endian): a `vertex` element with
//!   `x, y, z` of any scalar type; optional `nx, ny, nz`; optional
//!   `red, green, blue` (also `r, g, b` or `diffuse_red, …`), integers taken
//!   as 0–255 (`ushort` as 0–65535) and floats as 0–1; optional `radius`;
//!   optional clip lines for sharp features (§10.2.4), `clip0_angle,
//!   clip0_offset` and/or `clip1_angle, clip1_offset` (each pair complete):
//!   the kept side is `u·cos θ + v·sin θ ≤ c` in the tangent frame of the
//!   point's normal (see `clip`); an offset of `+inf` or ≥ `f32::MAX` is no
//!   line, other non-finite values are errors.
//!   Faces come from a `face` element (`vertex_indices` or `vertex_index`
//!   integer lists; polygons are fanned into triangles) and/or a `tristrips`
//!   element (`vertex_indices` lists, `-1` restarts a strip, the winding of
//!   every other triangle is flipped back, degenerate stitching triangles are
//!   dropped). A PLY whose faces/strips are non-empty is a
//!   [`PointInput::Mesh`] (a `radius` and clip lines are then ignored); otherwise
//!   [`PointInput::Points`]. Other elements are read and skipped.
//! * OBJ: triangulated into a single index buffer; vertex colours (`v x y z r
//!   g b`, 0–1, or 0–255 if any exceeds 1) when every vertex has them; normals
//!   when every vertex has one. With a single index a vertex is a distinct
//!   (position, texture coordinate, normal) triple of the faces, in order of
//!   first use: positions no face uses are dropped (the Stanford bunny's 35,947
//!   `v` lines give 34,834 vertices) and a position used with two normals
//!   becomes two vertices, so normals are always per-vertex consistent. Points
//!   and lines are ignored; materials are not read; objects and groups are
//!   merged.
//!
//! Everything is validated: the PLY format version (1.0), every element
//! count against [`MAX_PLY_ELEMENTS`] and against the bytes after the header
//! (before anything is allocated for it), indices in range, finite
//! coordinates and colours (the vertex index is named), at least one
//! point (a mesh: at least one triangle), radii positive and finite, nothing
//! after the last PLY element (a header whose counts are too small). OBJ
//! line statements (`l`) are not faces; a file of only lines has no faces.
//! Files are read through [`crate::io::read_input`] (its size cap and
//! regular-file check apply). Errors
//! are one line and name the file, e.g.
//! `bunny.ply: face 12 refers to vertex 9001 of 35947`.
//!
//! Normals are normalised; a zero-length or non-finite normal (scanners write
//! NaN for "unknown") becomes the zero vector, which means "unknown".
//!
//! ## Crates
//!
//! * PLY: [`ply_rs_bw`], the maintained fork of `ply-rs` (whose last release,
//!   0.1.3, still depends on the `linked-hash-map` of CVE-2020-25573, an old
//!   `peg` and a `skeptic` build dependency). The fork (releases through
//!   2026) forbids `unsafe`, runs a fuzz job in its CI, returns
//!   errors instead of panicking for malformed payloads, and caps the
//!   allocations it derives from header counts and list lengths, so a lying
//!   header cannot make it reserve gigabytes. Our tests cut a binary file at
//!   every byte and flip random bytes: always an error, never a panic.
//! * OBJ: [`tobj`], without default features (no `ahash`). tobj's MTL parser
//!   can panic on a short `Kd` line, so materials are never loaded; its face
//!   index arithmetic can overflow (a panic in builds with overflow checks) on
//!   absurd relative indices, so as a last resort the OBJ parse runs under
//!   [`std::panic::catch_unwind`] and such a panic becomes an ordinary error.
//!   OBJ has no counts, so a file cut exactly at a line break within the face
//!   list cannot be told from a complete one.

use std::io::{BufRead, BufReader};
use std::path::Path;

use glam::Vec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Property, PropertyAccess, PropertyAccessResult};

use super::clip::{ClipLine, ClipLines};
use crate::error::{Error, Result};
use crate::points::{PointCloud, TriangleMesh};
#[cfg(test)]
pub use header::MAX_PLY_ELEMENTS;
use header::{check_ply_header, check_ply_limits, payload_len};

/// The contents of a point input file (§10.1): a mesh to be sampled into
/// surfels, or points that already are surface samples.
#[derive(Clone, Debug, PartialEq)]
pub enum PointInput {
    /// A triangle mesh (PLY with faces or triangle strips, OBJ).
    Mesh(TriangleMesh),
    /// Points without connectivity (PLY without faces).
    Points(PointCloud),
}

impl PointInput {
    /// The vertex or point positions.
    pub fn positions(&self) -> &[Vec3] {
        match self {
            PointInput::Mesh(mesh) => &mesh.positions,
            PointInput::Points(cloud) => &cloud.positions,
        }
    }
}

/// Reads a mesh or point cloud (§10.1) from a `.ply` or `.obj` file (the
/// extension decides, in any case). Errors are one line and name the file.
pub fn load_points_file(path: &Path) -> Result<PointInput> {
    let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match extension.as_deref() {
        Some("ply") => load_ply(path),
        Some("obj") => load_obj(path).map(PointInput::Mesh),
        _ => Err(Error::input(
            path,
            "unsupported point input file type (accepted extensions: .ply, .obj)",
        )),
    }
}

/// Reads a PLY file (ASCII or binary, either endianness): a mesh if it has
/// faces or triangle strips, points otherwise (§10.1).
pub fn load_ply(path: &Path) -> Result<PointInput> {
    let bytes = crate::io::read_input(path)?;
    read_ply(&bytes, path)
}

/// Reads a Wavefront OBJ file into one triangle mesh (all objects and groups
/// merged; polygons fanned; §10.1).
pub fn load_obj(path: &Path) -> Result<TriangleMesh> {
    let bytes = crate::io::read_input(path)?;
    obj::read_obj(&bytes, path)
}

mod header;
mod obj;
#[cfg(test)]
mod tests;

// ---------------------------------------------------------------------------
// PLY

/// One PLY vertex as stored while parsing (compact: big scans have millions).
#[derive(Clone, Copy, Debug, Default)]
struct PlyVertex {
    position: [f32; 3],
    normal: [f32; 3],
    color: [u8; 3],
    radius: f32,
    /// `clip0_angle, clip0_offset, clip1_angle, clip1_offset`.
    clip: [f32; 4],
    /// A float colour channel was NaN or infinite (reported with the index).
    bad_color: bool,
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let slot = match vertex_slot(name) {
            Some(slot) => slot,
            None => return PropertyAccessResult::Ignored,
        };
        if let Slot::Color(i) = slot {
            if scalar_f64(&property).is_some_and(|v| !v.is_finite()) {
                self.bad_color = true;
            }
            return match color_byte(&property) {
                Some(c) => {
                    self.color[i] = c;
                    PropertyAccessResult::Set
                }
                None => PropertyAccessResult::UnsupportedType,
            };
        }
        let Some(value) = scalar_f64(&property) else {
            return PropertyAccessResult::UnsupportedType;
        };
        // f64 → f32 rounds; values beyond f32's range become ±inf and are
        // reported as non-finite by the validation.
        let value = value as f32;
        match slot {
            Slot::Position(i) => self.position[i] = value,
            Slot::Normal(i) => self.normal[i] = value,
            Slot::Radius => self.radius = value,
            Slot::Clip(i) => self.clip[i] = value,
            Slot::Color(_) => {}
        }
        PropertyAccessResult::Set
    }
}

/// One PLY face or triangle strip: its vertex index list.
#[derive(Clone, Debug, Default)]
struct PlyFace {
    indices: Vec<i64>,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if !is_index_list_name(name) {
            return PropertyAccessResult::Ignored;
        }
        match integer_list(property) {
            Some(list) => {
                self.indices = list;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::UnsupportedType,
        }
    }
}

/// An element we do not use (edges, materials, …): read and dropped.
#[derive(Clone, Copy, Debug, Default)]
struct PlySkip;

impl PropertyAccess for PlySkip {
    fn new() -> Self {
        PlySkip
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Slot {
    Position(usize),
    Normal(usize),
    Color(usize),
    Radius,
    /// `clip0_angle, clip0_offset, clip1_angle, clip1_offset`.
    Clip(usize),
}

/// The PLY names of the clip-line properties, in [`Slot::Clip`] order.
const CLIP_PROPERTIES: [&str; 4] = ["clip0_angle", "clip0_offset", "clip1_angle", "clip1_offset"];

fn vertex_slot(name: &str) -> Option<Slot> {
    Some(match name {
        "x" => Slot::Position(0),
        "y" => Slot::Position(1),
        "z" => Slot::Position(2),
        "nx" => Slot::Normal(0),
        "ny" => Slot::Normal(1),
        "nz" => Slot::Normal(2),
        "red" | "r" | "diffuse_red" => Slot::Color(0),
        "green" | "g" | "diffuse_green" => Slot::Color(1),
        "blue" | "b" | "diffuse_blue" => Slot::Color(2),
        "radius" => Slot::Radius,
        "clip0_angle" => Slot::Clip(0),
        "clip0_offset" => Slot::Clip(1),
        "clip1_angle" => Slot::Clip(2),
        "clip1_offset" => Slot::Clip(3),
        _ => return None,
    })
}

fn is_index_list_name(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

fn scalar_f64(property: &Property) -> Option<f64> {
    Some(match *property {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// A colour channel as a byte: 8-bit integers as they are, `ushort` scaled
/// from 0–65535, other integers clamped to 0–255, floats scaled from 0–1.
fn color_byte(property: &Property) -> Option<u8> {
    let unit = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8; // NaN → 0
    let clamp = |v: i64| v.clamp(0, 255) as u8;
    Some(match *property {
        Property::UChar(v) => v,
        Property::Char(v) => clamp(i64::from(v)),
        Property::Short(v) => clamp(i64::from(v)),
        Property::UShort(v) => (f64::from(v) / 257.0).round() as u8,
        Property::Int(v) => clamp(i64::from(v)),
        Property::UInt(v) => clamp(i64::from(v)),
        Property::Float(v) => unit(f64::from(v)),
        Property::Double(v) => unit(v),
        _ => return None,
    })
}

fn integer_list(property: Property) -> Option<Vec<i64>> {
    fn widen<T: Copy + Into<i64>>(list: Vec<T>) -> Vec<i64> {
        list.into_iter().map(Into::into).collect()
    }
    Some(match property {
        Property::ListChar(l) => widen(l),
        Property::ListUChar(l) => widen(l),
        Property::ListShort(l) => widen(l),
        Property::ListUShort(l) => widen(l),
        Property::ListInt(l) => widen(l),
        Property::ListUInt(l) => widen(l),
        _ => return None,
    })
}

/// Makes a parser message one short line.
fn one_line(message: &str) -> String {
    const MAX: usize = 200;
    let mut out = String::with_capacity(message.len().min(MAX + 8));
    let mut last_space = true;
    let mut count = 0;
    for c in message.chars() {
        let c = if c.is_control() || c.is_whitespace() {
            ' '
        } else if c == char::REPLACEMENT_CHARACTER {
            '?'
        } else {
            c
        };
        if c == ' ' && last_space {
            continue;
        }
        last_space = c == ' ';
        if count >= MAX {
            out.push('…');
            break;
        }
        out.push(c);
        count += 1;
    }
    out.trim_end().to_string()
}

/// Whether anything but whitespace follows in `reader`.
fn has_trailing_data(reader: &mut impl BufRead) -> std::io::Result<bool> {
    loop {
        let buf = reader.fill_buf()?;
        if buf.is_empty() {
            return Ok(false);
        }
        if buf.iter().any(|b| !b.is_ascii_whitespace()) {
            return Ok(true);
        }
        let n = buf.len();
        reader.consume(n);
    }
}

/// Parses a PLY stream; `path` names the file in errors.
fn read_ply(bytes: &[u8], path: &Path) -> Result<PointInput> {
    let bad = |message: String| Error::input(path, message);
    let parse_error = |e: ply_rs_bw::parser::ParseError| bad(one_line(&format!("invalid PLY: {e}")));

    let mut reader = Reader::new(BufReader::new(bytes));
    let header = Parser::<PlySkip>::new().read_header(&mut reader).map_err(parse_error)?;
    let layout = check_ply_header(&header).map_err(bad)?;
    check_ply_limits(&header, payload_len(bytes).unwrap_or(0)).map_err(bad)?;

    let mut vertices: Vec<PlyVertex> = Vec::new();
    let mut faces: Vec<PlyFace> = Vec::new();
    let mut strips: Vec<PlyFace> = Vec::new();
    for (name, def) in &header.elements {
        match name.as_str() {
            "vertex" => {
                vertices = Parser::<PlyVertex>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(parse_error)?
            }
            "face" => {
                faces = Parser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(parse_error)?
            }
            "tristrips" => {
                strips = Parser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(parse_error)?
            }
            _ => {
                Parser::<PlySkip>::new()
                    .read_payload_for_element(&mut reader, def, &header)
                    .map_err(parse_error)?;
            }
        }
    }
    match has_trailing_data(reader.get_mut()) {
        Ok(false) => {}
        Ok(true) => {
            return Err(bad(
                "data after the last PLY element (the header's element counts are too small)".to_string(),
            ))
        }
        Err(e) => return Err(bad(format!("cannot read: {e}"))),
    }

    let n = vertices.len();
    if n == 0 {
        return Err(bad("PLY file has no vertices".to_string()));
    }
    if u32::try_from(n - 1).is_err() {
        return Err(bad(format!(
            "PLY file has {n} vertices, more than 32-bit indices can address"
        )));
    }
    let mut positions = Vec::with_capacity(n);
    for (i, v) in vertices.iter().enumerate() {
        let p = Vec3::from_array(v.position);
        if !p.is_finite() {
            return Err(bad(format!(
                "vertex {i} has a non-finite coordinate ({}, {}, {})",
                p.x, p.y, p.z
            )));
        }
        if v.bad_color {
            return Err(bad(format!("vertex {i} has a non-finite colour")));
        }
        positions.push(p);
    }
    let normals = layout.normals.then(|| {
        vertices
            .iter()
            .map(|v| unit_or_zero(Vec3::from_array(v.normal)))
            .collect()
    });
    let colors = layout.colors.then(|| vertices.iter().map(|v| v.color).collect());

    if faces.is_empty() && strips.is_empty() {
        let radii = layout.radius.then(|| ply_radii(&vertices)).transpose().map_err(bad)?;
        let clip = (layout.clip.contains(&true))
            .then(|| ply_clip_lines(&vertices, layout.clip))
            .transpose()
            .map_err(bad)?;
        return Ok(PointInput::Points(PointCloud {
            positions,
            normals,
            colors,
            radii,
            clip,
        }));
    }
    drop(vertices);

    let triangles = ply_triangles(&faces, &strips, n).map_err(bad)?;
    if triangles.is_empty() {
        return Err(bad("PLY faces and strips give no triangles".to_string()));
    }
    Ok(PointInput::Mesh(TriangleMesh {
        positions,
        normals,
        colors,
        triangles,
    }))
}

/// The splat radii of PLY vertices; the message names a vertex whose
/// radius is not positive and finite.
fn ply_radii(vertices: &[PlyVertex]) -> std::result::Result<Vec<f32>, String> {
    (vertices.iter().enumerate())
        .map(|(i, v)| match v.radius.is_finite() && v.radius > 0.0 {
            true => Ok(v.radius),
            false => Err(format!(
                "vertex {i} has radius {} (must be positive and finite)",
                v.radius
            )),
        })
        .collect()
}

/// The clip lines of PLY vertices (`present`: which of the two lines the
/// header has); the message names a vertex with a non-finite line.
fn ply_clip_lines(vertices: &[PlyVertex], present: [bool; 2]) -> std::result::Result<Vec<ClipLines>, String> {
    (vertices.iter().enumerate())
        .map(|(i, v)| {
            clip_lines(v, present).ok_or_else(|| {
                format!(
                    "vertex {i} has a non-finite clip line ({}, {}, {}, {})",
                    v.clip[0], v.clip[1], v.clip[2], v.clip[3]
                )
            })
        })
        .collect()
}

/// The triangles of PLY faces (fanned) and strips (`-1` restarts) over `n`
/// vertices; the message names the face or strip with a bad index.
fn ply_triangles(faces: &[PlyFace], strips: &[PlyFace], n: usize) -> std::result::Result<Vec<[u32; 3]>, String> {
    let mut triangles = Vec::with_capacity(faces.len() + strips.len());
    let index = |v: i64, what: &str, k: usize| -> std::result::Result<u32, String> {
        match u32::try_from(v) {
            Ok(i) if (i as usize) < n => Ok(i),
            _ => Err(format!("{what} {k} refers to vertex {v} of {n}")),
        }
    };
    for (k, face) in faces.iter().enumerate() {
        let list = &face.indices;
        if list.len() < 3 {
            return Err(format!("face {k} has {} vertices (at least 3 needed)", list.len()));
        }
        let first = index(list[0], "face", k)?;
        let mut previous = index(list[1], "face", k)?;
        for &v in &list[2..] {
            let current = index(v, "face", k)?;
            triangles.push([first, previous, current]);
            previous = current;
        }
    }
    let mut run: Vec<u32> = Vec::new();
    for (k, strip) in strips.iter().enumerate() {
        run.clear();
        for &v in &strip.indices {
            if v == -1 {
                unroll_strip(&run, &mut triangles);
                run.clear();
            } else {
                run.push(index(v, "triangle strip", k)?);
            }
        }
        unroll_strip(&run, &mut triangles);
    }
    Ok(triangles)
}

/// The clip lines of a PLY vertex (`present`: which of the two the header
/// has); `None` when a present line has a NaN or infinite value other than
/// the offset `+inf`, which, like offsets ≥ `f32::MAX`, means "no line".
fn clip_lines(v: &PlyVertex, present: [bool; 2]) -> Option<ClipLines> {
    let mut lines = ClipLines::NONE;
    for (k, &present) in present.iter().enumerate() {
        let (angle, offset) = (v.clip[2 * k], v.clip[2 * k + 1]);
        if !present || offset >= f32::MAX {
            continue;
        }
        if !(angle.is_finite() && offset.is_finite()) {
            return None;
        }
        lines.0[k] = Some(ClipLine { angle, offset });
    }
    Some(lines)
}

/// Appends the triangles of one strip (no restarts in `run`): triangle `i`
/// is `(v[i], v[i+1], v[i+2])` for even `i` and `(v[i+1], v[i], v[i+2])` for
/// odd `i`, so all keep the first one's winding. Degenerate triangles (used to
/// stitch strips together) are dropped.
fn unroll_strip(run: &[u32], triangles: &mut Vec<[u32; 3]>) {
    for (i, w) in run.windows(3).enumerate() {
        let (a, b, c) = if i % 2 == 0 {
            (w[0], w[1], w[2])
        } else {
            (w[1], w[0], w[2])
        };
        if a != b && b != c && a != c {
            triangles.push([a, b, c]);
        }
    }
}

fn unit_or_zero(n: Vec3) -> Vec3 {
    if n.is_finite() {
        n.normalize_or_zero()
    } else {
        Vec3::ZERO
    }
}
