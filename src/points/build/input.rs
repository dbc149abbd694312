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
//! Everything is validated: indices in range, finite coordinates, at least one
//! point (a mesh: at least one triangle), radii positive and finite, nothing
//! after the last PLY element (a header whose counts are too small). Errors
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

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use glam::Vec3;
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType};

use super::clip::{ClipLine, ClipLines};
use crate::error::{Error, Result};
use crate::points::{PointCloud, TriangleMesh};

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
    let file = File::open(path).map_err(|e| Error::input(path, format!("cannot open: {e}")))?;
    read_ply(file, path)
}

/// Reads a Wavefront OBJ file into one triangle mesh (all objects and groups
/// merged; polygons fanned; §10.1).
pub fn load_obj(path: &Path) -> Result<TriangleMesh> {
    let file = File::open(path).map_err(|e| Error::input(path, format!("cannot open: {e}")))?;
    read_obj(BufReader::new(file), path)
}

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

fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

/// What the header says about the vertex element.
#[derive(Clone, Copy, Debug, Default)]
struct VertexLayout {
    normals: bool,
    colors: bool,
    radius: bool,
    /// Whether clip line 0 / 1 is present (both of its properties).
    clip: [bool; 2],
}

/// Checks the header for what we need and returns the vertex layout.
fn check_ply_header(header: &Header) -> std::result::Result<VertexLayout, String> {
    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| "PLY header has no 'vertex' element".to_string())?;
    let mut seen = [false; 14];
    for (name, def) in &vertex.properties {
        let Some(slot) = vertex_slot(name) else { continue };
        if !matches!(def.data_type, PropertyType::Scalar(_)) {
            return Err(format!("PLY vertex property '{name}' is a list, expected a number"));
        }
        let k = match slot {
            Slot::Position(i) => i,
            Slot::Normal(i) => 3 + i,
            Slot::Color(i) => 6 + i,
            Slot::Radius => 9,
            Slot::Clip(i) => 10 + i,
        };
        seen[k] = true;
    }
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        if !seen[i] {
            return Err(format!("PLY vertex element has no property '{axis}'"));
        }
    }
    for k in 0..2 {
        let (angle, offset) = (10 + 2 * k, 11 + 2 * k);
        if seen[angle] != seen[offset] {
            let (has, lacks) = if seen[angle] { (angle, offset) } else { (offset, angle) };
            return Err(format!(
                "PLY vertex property '{}' without '{}'",
                CLIP_PROPERTIES[has - 10],
                CLIP_PROPERTIES[lacks - 10]
            ));
        }
    }
    for element in ["face", "tristrips"] {
        let Some(def) = header.elements.get(element) else {
            continue;
        };
        let list = def.properties.iter().find(|(name, _)| is_index_list_name(name));
        match list {
            Some((name, p)) => match &p.data_type {
                PropertyType::List(_, t) if is_integer(t) => {}
                _ => return Err(format!("PLY {element} property '{name}' is not a list of integers")),
            },
            None if def.count > 0 => {
                return Err(format!("PLY {element} element has no 'vertex_indices' list"));
            }
            None => {}
        }
    }
    Ok(VertexLayout {
        normals: seen[3] && seen[4] && seen[5],
        colors: seen[6] && seen[7] && seen[8],
        radius: seen[9],
        clip: [seen[10], seen[12]],
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
fn read_ply(source: impl Read, path: &Path) -> Result<PointInput> {
    let bad = |message: String| Error::input(path, message);
    let parse_error = |e: ply_rs_bw::parser::ParseError| bad(one_line(&format!("invalid PLY: {e}")));

    let mut reader = Reader::new(BufReader::new(source));
    let header = Parser::<PlySkip>::new().read_header(&mut reader).map_err(parse_error)?;
    let layout = check_ply_header(&header).map_err(bad)?;

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
        let radii = if layout.radius {
            let mut radii = Vec::with_capacity(n);
            for (i, v) in vertices.iter().enumerate() {
                if !(v.radius.is_finite() && v.radius > 0.0) {
                    return Err(bad(format!(
                        "vertex {i} has radius {} (must be positive and finite)",
                        v.radius
                    )));
                }
                radii.push(v.radius);
            }
            Some(radii)
        } else {
            None
        };
        let clip = if layout.clip.contains(&true) {
            let mut clip = Vec::with_capacity(n);
            for (i, v) in vertices.iter().enumerate() {
                clip.push(clip_lines(v, layout.clip).ok_or_else(|| {
                    bad(format!(
                        "vertex {i} has a non-finite clip line ({}, {}, {}, {})",
                        v.clip[0], v.clip[1], v.clip[2], v.clip[3]
                    ))
                })?);
            }
            Some(clip)
        } else {
            None
        };
        return Ok(PointInput::Points(PointCloud {
            positions,
            normals,
            colors,
            radii,
            clip,
        }));
    }
    drop(vertices);

    let mut triangles = Vec::with_capacity(faces.len() + strips.len());
    let index = |v: i64, what: &str, k: usize| -> Result<u32> {
        match u32::try_from(v) {
            Ok(i) if (i as usize) < n => Ok(i),
            _ => Err(bad(format!("{what} {k} refers to vertex {v} of {n}"))),
        }
    };
    for (k, face) in faces.iter().enumerate() {
        let list = &face.indices;
        if list.len() < 3 {
            return Err(bad(format!("face {k} has {} vertices (at least 3 needed)", list.len())));
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

// ---------------------------------------------------------------------------
// OBJ

/// Parses an OBJ stream; `path` names the file in errors.
fn read_obj(mut reader: impl BufRead, path: &Path) -> Result<TriangleMesh> {
    let bad = |message: String| Error::input(path, message);
    // Triangulated, single index, points and lines dropped.
    let options = tobj::GPU_LOAD_OPTIONS;
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        // Materials are never loaded (see the module documentation).
        tobj::load_obj_buf(&mut reader, &options, |_| Err(tobj::LoadError::GenericFailure))
    }));
    let models = match parsed {
        Ok(Ok((models, _materials))) => models,
        Ok(Err(tobj::LoadError::ReadError)) => {
            return Err(bad("invalid OBJ: cannot read (not UTF-8 text?)".to_string()));
        }
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
    use super::*;
    use std::path::PathBuf;

    fn data(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
    }

    /// A scratch file in the system temporary directory, removed on drop.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(name: &str, bytes: &[u8]) -> Scratch {
            let path = std::env::temp_dir().join(format!("alpenglow-points-input-{}-{name}", std::process::id()));
            std::fs::write(&path, bytes).expect("write scratch file");
            Scratch(path)
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_file(&self.0);
        }
    }

    fn parse(bytes: &[u8]) -> Result<PointInput> {
        read_ply(bytes, Path::new("test.ply"))
    }

    fn mesh(input: PointInput) -> TriangleMesh {
        match input {
            PointInput::Mesh(m) => m,
            PointInput::Points(_) => panic!("expected a mesh"),
        }
    }

    fn points(input: PointInput) -> PointCloud {
        match input {
            PointInput::Points(p) => p,
            PointInput::Mesh(_) => panic!("expected points"),
        }
    }

    fn err(result: Result<PointInput>) -> String {
        let message = result.expect_err("expected an error").to_string();
        assert!(!message.contains('\n'), "multi-line error: {message:?}");
        message
    }

    /// Builds PLY payloads in either byte order.
    struct Bin {
        little: bool,
        bytes: Vec<u8>,
    }

    impl Bin {
        fn new(header: &str, little: bool) -> Bin {
            Bin {
                little,
                bytes: header.as_bytes().to_vec(),
            }
        }
        fn put<const N: usize>(&mut self, le: [u8; N], be: [u8; N]) -> &mut Self {
            self.bytes.extend_from_slice(if self.little { &le } else { &be });
            self
        }
        fn f32(&mut self, v: f32) -> &mut Self {
            self.put(v.to_le_bytes(), v.to_be_bytes())
        }
        fn f64(&mut self, v: f64) -> &mut Self {
            self.put(v.to_le_bytes(), v.to_be_bytes())
        }
        fn i32(&mut self, v: i32) -> &mut Self {
            self.put(v.to_le_bytes(), v.to_be_bytes())
        }
        fn u32(&mut self, v: u32) -> &mut Self {
            self.put(v.to_le_bytes(), v.to_be_bytes())
        }
        fn u8(&mut self, v: u8) -> &mut Self {
            self.bytes.push(v);
            self
        }
    }

    const SQUARE: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];

    /// A unit square as a quad plus a lone triangle, float positions, uchar
    /// colours, `int` indices, in the given byte order.
    fn binary_square(little: bool, vertex_count: usize) -> Vec<u8> {
        let format = if little {
            "binary_little_endian"
        } else {
            "binary_big_endian"
        };
        let header = format!(
            "ply\nformat {format} 1.0\ncomment made by the test\nelement vertex {vertex_count}\n\
             property float x\nproperty float y\nproperty float z\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\n\
             element face 2\nproperty list uchar int vertex_indices\nend_header\n"
        );
        let mut b = Bin::new(&header, little);
        for (i, p) in SQUARE.iter().enumerate() {
            b.f32(p[0]).f32(p[1]).f32(p[2]).u8(10 * i as u8).u8(20).u8(255);
        }
        b.u8(4).i32(0).i32(1).i32(2).i32(3);
        b.u8(3).i32(0).i32(2).i32(3);
        b.bytes
    }

    fn check_binary_square(m: &TriangleMesh) {
        let expected: Vec<Vec3> = SQUARE.iter().map(|&p| Vec3::from_array(p)).collect();
        assert_eq!(m.positions, expected);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert_eq!(
            m.colors,
            Some(vec![[0, 20, 255], [10, 20, 255], [20, 20, 255], [30, 20, 255]])
        );
        assert_eq!(m.normals, None);
    }

    #[test]
    fn ascii_ply_mesh_with_normals_from_fixture() {
        let m = mesh(load_points_file(&data("points/quad.ply")).unwrap());
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
        // The quad is fanned from its first vertex; the winding is kept.
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals, Some(vec![Vec3::Z; 4]));
        assert_eq!(m.colors, None);
    }

    #[test]
    fn ascii_ply_points_with_int_and_double_coordinates() {
        let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty int x\nproperty double y\n\
                    property short z\nproperty float confidence\nend_header\n1 2.5 -3 0.9\n-4 5e-1 6 1\n";
        let p = points(parse(text.as_bytes()).unwrap());
        assert_eq!(p.positions, vec![Vec3::new(1.0, 2.5, -3.0), Vec3::new(-4.0, 0.5, 6.0)]);
        assert_eq!((p.normals, p.colors, p.radii), (None, None, None));
    }

    #[test]
    fn binary_little_endian_ply() {
        let bytes = binary_square(true, 4);
        let file = Scratch::new("le.ply", &bytes);
        check_binary_square(&mesh(load_points_file(&file.0).unwrap()));
    }

    #[test]
    fn binary_big_endian_ply() {
        let bytes = binary_square(false, 4);
        let file = Scratch::new("be.PLY", &bytes);
        check_binary_square(&mesh(load_points_file(&file.0).unwrap()));
    }

    #[test]
    fn binary_big_endian_doubles_uint_indices_and_extra_elements() {
        let header = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n\
                      property double y\nproperty double z\nproperty float nx\nproperty float ny\n\
                      property float nz\nelement face 1\nproperty uchar flags\n\
                      property list uchar uint vertex_index\nelement edge 1\nproperty int vertex1\n\
                      property int vertex2\nend_header\n";
        let mut b = Bin::new(header, false);
        for (p, n) in [(0.0, 2.0), (1.0, 0.0), (2.0, -1.0)] {
            b.f64(p).f64(p * 2.0).f64(1e10).f32(0.0).f32(0.0).f32(n);
        }
        b.u8(7).u8(3).u32(2).u32(1).u32(0);
        b.i32(0).i32(1);
        let m = mesh(parse(&b.bytes).unwrap());
        assert_eq!(m.positions[2], Vec3::new(2.0, 4.0, 1e10));
        assert_eq!(m.triangles, vec![[2, 1, 0]]);
        // Normalised; the zero normal stays zero ("unknown").
        assert_eq!(m.normals, Some(vec![Vec3::Z, Vec3::ZERO, -Vec3::Z]));
    }

    #[test]
    fn ply_tristrips_with_restart_and_alternating_winding() {
        let m = mesh(load_points_file(&data("points/strip.ply")).unwrap());
        assert_eq!(m.positions.len(), 6);
        // Strip 0 1 2 3 4, restart, strip 5 4 3 (all counter-clockwise seen
        // from +z); the degenerate 4 4 5 stitch in the second strip is dropped.
        assert_eq!(m.triangles, vec![[0, 1, 2], [2, 1, 3], [2, 3, 4], [5, 4, 3]]);
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "triangle {t:?} is clockwise");
        }
    }

    #[test]
    fn ply_points_with_float_colors_and_radius() {
        let p = points(load_points_file(&data("points/colored-points.ply")).unwrap());
        assert_eq!(p.positions.len(), 3);
        assert_eq!(p.colors, Some(vec![[255, 0, 0], [0, 128, 0], [0, 0, 255]]));
        assert_eq!(p.radii, Some(vec![0.5, 0.25, 2.0]));
        assert_eq!(p.normals.as_ref().map(Vec::len), Some(3));
        assert_eq!(p.normals.unwrap()[1], Vec3::Y);
    }

    #[test]
    fn ply_points_with_clip_lines() {
        let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                      property float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
                      property float clip0_angle\nproperty float clip0_offset\n\
                      property float clip1_angle\nproperty float clip1_offset\nend_header\n";
        let body = "0 0 0 0 0 1 0.5 0.1 1.0 3.4028235e38\n\
                    1 0 0 0 0 1 0 0.2 1.5 -0.125\n\
                    2 0 0 0 0 1 0 3.4028235e38 0 3.4028235e38\n";
        let file = Scratch::new("clip.ply", format!("{header}{body}").as_bytes());
        let p = points(load_points_file(&file.0).unwrap());
        let line = |angle, offset| Some(ClipLine { angle, offset });
        assert_eq!(
            p.clip,
            Some(vec![
                ClipLines([line(0.5, 0.1), None]),
                ClipLines([line(0.0, 0.2), line(1.5, -0.125)]),
                ClipLines::NONE,
            ])
        );
        // One line only; the other clip fields absent.
        let one = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                   property float z\nproperty double clip0_offset\nproperty float clip0_angle\n\
                   end_header\n0 0 0 0.25 -1\n";
        let p = points(parse(one.as_bytes()).unwrap());
        assert_eq!(p.clip, Some(vec![ClipLines([line(-1.0, 0.25), None])]));
        // Without clip properties there are none.
        let plain = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                     property float z\nend_header\n0 0 0\n";
        assert_eq!(points(parse(plain.as_bytes()).unwrap()).clip, None);
        // An incomplete pair, a NaN, a −inf offset: errors.
        let half = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                    property float z\nproperty float clip1_angle\nend_header\n0 0 0 1\n";
        let message = err(parse(half.as_bytes()));
        assert!(message.contains("'clip1_angle' without 'clip1_offset'"), "{message}");
        // (ASCII PLY has no NaN or infinity: binary.)
        let header = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n\
                      property float y\nproperty float z\nproperty float clip0_angle\n\
                      property float clip0_offset\nend_header\n";
        for (angle, offset) in [(f32::NAN, 0.1), (0.5, f32::NEG_INFINITY), (f32::INFINITY, 0.1)] {
            let mut b = Bin::new(header, true);
            b.f32(0.0).f32(0.0).f32(0.0).f32(0.0).f32(0.1);
            b.f32(1.0).f32(1.0).f32(1.0).f32(angle).f32(offset);
            let message = err(parse(&b.bytes));
            assert!(message.contains("vertex 1 has a non-finite clip line"), "{message}");
        }
        // An infinite offset is no line, whatever the angle.
        let mut b = Bin::new(header, true);
        b.f32(0.0).f32(0.0).f32(0.0).f32(f32::NAN).f32(f32::INFINITY);
        b.f32(1.0).f32(1.0).f32(1.0).f32(0.0).f32(0.5);
        assert_eq!(
            points(parse(&b.bytes).unwrap()).clip,
            Some(vec![ClipLines::NONE, ClipLines([line(0.0, 0.5), None])])
        );
        // Meshes ignore them.
        let mesh_text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                         property float z\nproperty float clip0_angle\nproperty float clip0_offset\n\
                         element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                         0 0 0 0 -7\n1 0 0 0 0\n0 1 0 0 0\n3 0 1 2\n";
        assert_eq!(mesh(parse(mesh_text.as_bytes()).unwrap()).triangles.len(), 1);
    }

    #[test]
    fn ply_radius_must_be_positive() {
        let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                    property float z\nproperty float radius\nend_header\n0 0 0 1\n1 1 1 0\n";
        let message = err(parse(text.as_bytes()));
        assert!(message.contains("vertex 1 has radius 0"), "{message}");
    }

    #[test]
    fn truncated_binary_ply_is_an_error_at_every_length() {
        for little in [true, false] {
            let bytes = binary_square(little, 4);
            assert!(parse(&bytes).is_ok());
            for len in 0..bytes.len() {
                let message = err(parse(&bytes[..len]));
                assert!(message.starts_with("test.ply: "), "{message}");
            }
        }
    }

    #[test]
    fn corrupted_ply_never_panics() {
        // Flip random bytes (a fixed linear congruential sequence) in binary
        // and ASCII files; every outcome must be a result, not a panic.
        let ascii = std::fs::read(data("points/strip.ply")).unwrap();
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) as usize
        };
        for original in [binary_square(true, 4), binary_square(false, 4), ascii] {
            for _ in 0..400 {
                let mut bytes = original.clone();
                for _ in 0..1 + next() % 4 {
                    let i = next() % bytes.len();
                    bytes[i] = next() as u8;
                }
                if let Err(e) = parse(&bytes) {
                    assert!(!e.to_string().contains('\n'));
                }
            }
        }
    }

    #[test]
    fn header_counts_that_lie_are_errors() {
        // Too many vertices: the faces are read as a vertex, the rest fails.
        let message = err(parse(&binary_square(true, 5)));
        assert!(message.starts_with("test.ply: "), "{message}");
        // Too few: data is left over after the last element.
        let message = err(parse(&binary_square(false, 3)));
        assert!(message.starts_with("test.ply: "), "{message}");
        // The same in ASCII, with the checked-in fixture.
        let message = err(load_points_file(&data("points/short-count.ply")));
        assert!(
            message.contains("short-count.ply: data after the last PLY element"),
            "{message}"
        );
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nend_header\n0 0 0\n1 1 1\n";
        let message = err(parse(text.as_bytes()));
        assert!(message.contains("Unexpected end of file"), "{message}");
    }

    #[test]
    fn bad_face_index_is_an_error_naming_face_and_vertex() {
        let message = err(load_points_file(&data("points/bad-index.ply")));
        assert!(
            message.ends_with("bad-index.ply: face 1 refers to vertex 9001 of 4"),
            "{message}"
        );
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nelement tristrips 1\nproperty list int int vertex_indices\n\
                    end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2 -2\n";
        let message = err(parse(text.as_bytes()));
        assert_eq!(message, "test.ply: triangle strip 0 refers to vertex -2 of 3");
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                    end_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n";
        let message = err(parse(text.as_bytes()));
        assert_eq!(message, "test.ply: face 0 has 2 vertices (at least 3 needed)");
    }

    /// A PLY file: header lines between the format and `end_header`, then `body`.
    fn ply(format: &str, header: &str, body: &[u8]) -> Vec<u8> {
        let mut bytes = format!("ply\nformat {format} 1.0\n{header}end_header\n").into_bytes();
        bytes.extend_from_slice(body);
        bytes
    }

    const XYZ: &str = "property float x\nproperty float y\nproperty float z\n";

    #[test]
    fn malformed_ply_headers_and_values_are_errors() {
        let vertex = |count: &str| format!("element vertex {count}\n{XYZ}");
        let list_x = "element vertex 1\nproperty list uchar float x\nproperty float y\nproperty float z\n";
        let float_list = format!(
            "{}element face 1\nproperty list uchar float vertex_indices\n",
            vertex("3")
        );
        let no_z = "element vertex 1\nproperty float x\nproperty float y\n";
        let cases: [(Vec<u8>, &str); 8] = [
            (Vec::new(), "invalid PLY"),
            (b"not a ply file\n".to_vec(), "invalid PLY"),
            (ply("ascii", &vertex("0"), b""), "no vertices"),
            (
                ply("ascii", "element point 1\nproperty float x\n", b"1\n"),
                "no 'vertex' element",
            ),
            (ply("ascii", no_z, b"1 2\n"), "no property 'z'"),
            (ply("ascii", &vertex("1"), b"1 2 x\n"), "invalid PLY"),
            (ply("ascii", list_x, b"1 1 2 3\n"), "'x' is a list"),
            (
                ply("ascii", &float_list, b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                "not a list of integers",
            ),
        ];
        for (bytes, expected) in &cases {
            let message = err(parse(bytes));
            assert!(message.contains(expected), "{message:?} lacks {expected:?}");
        }

        let nan: Vec<u8> = f32::NAN.to_le_bytes().into_iter().chain([0; 8]).collect();
        let message = err(parse(&ply("binary_little_endian", &vertex("1"), &nan)));
        assert_eq!(message, "test.ply: vertex 0 has a non-finite coordinate (NaN, 0, 0)");
        let doubles = "element vertex 1\nproperty double x\nproperty double y\nproperty double z\n";
        let huge: Vec<u8> = [1e300f64, 0.0, 0.0].iter().flat_map(|v| v.to_be_bytes()).collect();
        let message = err(parse(&ply("binary_big_endian", doubles, &huge)));
        assert_eq!(message, "test.ply: vertex 0 has a non-finite coordinate (inf, 0, 0)");
    }

    #[test]
    fn absurd_ply_counts_are_errors_without_huge_allocations() {
        for count in ["18446744073709551615", "99999999999999999999999"] {
            let message = err(parse(&ply(
                "binary_little_endian",
                &format!("element vertex {count}\n{XYZ}"),
                b"",
            )));
            assert!(message.starts_with("test.ply: invalid PLY: "), "{message}");
        }
        let header = format!("element vertex 1\n{XYZ}element face 1\nproperty list uint int vertex_indices\n");
        let body: Vec<u8> = [0u8; 12]
            .into_iter()
            .chain(u32::MAX.to_le_bytes())
            .chain([0; 12])
            .collect();
        let message = err(parse(&ply("binary_little_endian", &header, &body)));
        assert!(message.starts_with("test.ply: invalid PLY: "), "{message}");
        // A parser message quoting a long line is cut to one short line.
        let long = format!("{} x\n", "1 ".repeat(5000));
        let message = err(parse(&ply(
            "ascii",
            &format!("element vertex 1\n{XYZ}"),
            long.as_bytes(),
        )));
        assert!(message.len() < 300, "{message}");
    }

    #[test]
    fn unknown_extension_and_missing_file_are_errors() {
        let message = load_points_file(Path::new("scan.xyz")).unwrap_err().to_string();
        assert_eq!(
            message,
            "scan.xyz: unsupported point input file type (accepted extensions: .ply, .obj)"
        );
        let message = load_points_file(Path::new("no-extension")).unwrap_err().to_string();
        assert!(message.starts_with("no-extension: unsupported"), "{message}");
        let message = load_points_file(Path::new("/nonexistent/bunny.ply"))
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with("/nonexistent/bunny.ply: cannot open: "),
            "{message}"
        );
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
                "OBJ vertex has a non-finite coordinate (NaN, 0, 0)",
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
        let message = read_obj(&b"v 0 0 \xff\n"[..], Path::new("t.obj"))
            .unwrap_err()
            .to_string();
        assert!(message.starts_with("t.obj: invalid OBJ"), "{message}");
    }
}
