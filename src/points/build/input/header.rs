//! PLY header checks: the vertex layout we need, the format version, and the
//! element counts against the bytes that follow the header and
//! [`MAX_PLY_ELEMENTS`], all before any element is read (so a lying header
//! cannot make the parser allocate or loop for long).

use ply_rs_bw::ply::{Encoding, Header, PropertyType, ScalarType};

use super::{is_index_list_name, vertex_slot, Slot, CLIP_PROPERTIES};

/// Most elements of one kind (vertices, faces, strips, others) a PLY file
/// may declare: 100 million, about 1.2 GB of `float` positions. Larger
/// scans are split or decimated first.
pub const MAX_PLY_ELEMENTS: usize = 100_000_000;

pub(super) fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

/// What the header says about the vertex element.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct VertexLayout {
    pub normals: bool,
    pub colors: bool,
    pub radius: bool,
    /// Whether clip line 0 / 1 is present (both of its properties).
    pub clip: [bool; 2],
}

/// Checks the header for what we need and returns the vertex layout.
pub(super) fn check_ply_header(header: &Header) -> std::result::Result<VertexLayout, String> {
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

/// Bytes one element needs at least: in binary the scalars and list counts,
/// in ASCII two characters (a digit and a separator) per property.
fn min_element_bytes(encoding: Encoding, properties: &[&PropertyType]) -> u128 {
    let scalar = |t: &ScalarType| -> u128 {
        match t {
            ScalarType::Char | ScalarType::UChar => 1,
            ScalarType::Short | ScalarType::UShort => 2,
            ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
            ScalarType::Double => 8,
        }
    };
    match encoding {
        Encoding::Ascii => 2 * properties.len() as u128,
        Encoding::BinaryBigEndian | Encoding::BinaryLittleEndian => properties
            .iter()
            .map(|p| match p {
                PropertyType::Scalar(t) => scalar(t),
                PropertyType::List(count, _) => scalar(count),
            })
            .sum(),
    }
}

/// Checks the version (1.0 only) and every element count against
/// [`MAX_PLY_ELEMENTS`] and the `payload` bytes after `end_header`.
pub(super) fn check_ply_limits(header: &Header, payload: usize) -> std::result::Result<(), String> {
    let v = header.version;
    if (v.major, v.minor) != (1, 0) {
        return Err(format!("unsupported PLY format version {v} (only 1.0 is defined)"));
    }
    let mut needed: u128 = 0;
    for (name, def) in &header.elements {
        if def.count > MAX_PLY_ELEMENTS {
            return Err(format!(
                "PLY element '{name}' has {} entries, more than the limit of {MAX_PLY_ELEMENTS}",
                def.count
            ));
        }
        let properties: Vec<&PropertyType> = def.properties.iter().map(|(_, p)| &p.data_type).collect();
        needed += def.count as u128 * min_element_bytes(header.encoding, &properties);
    }
    // ASCII: the last value needs no separator.
    let slack = u128::from(header.encoding == Encoding::Ascii);
    if needed > payload as u128 + slack {
        return Err(format!(
            "the PLY header's element counts need at least {needed} bytes, but only {payload} follow the header"
        ));
    }
    Ok(())
}

/// Bytes after the header line `end_header` (and its line break), if any.
pub(super) fn payload_len(bytes: &[u8]) -> Option<usize> {
    const END: &[u8] = b"\nend_header";
    let at = bytes.windows(END.len()).position(|w| w == END)? + END.len();
    let rest = &bytes[at..];
    let skip = if rest.starts_with(b"\r\n") {
        2
    } else {
        usize::from(rest.starts_with(b"\n") || rest.starts_with(b"\r"))
    };
    Some(rest.len() - skip)
}
