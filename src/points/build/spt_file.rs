//! Sequential point tree files (dissertation §10.1; `ALGORITHMS.md` §7): the
//! output of [`super::spt::build_spt`], stored so that renderers need not
//! rebuild the tree.
//!
//! # Layout (version 2, all little-endian)
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `b"ALPSPT\0\0"` |
//! | 8 | 4 | u32 version = 2 |
//! | 12 | 4 | u32 node count N (≥ 1) |
//! | 16 | 4 | f32 ε |
//! | 20 | 12 | f32×3 bounds centre |
//! | 32 | 4 | f32 bounds radius |
//! | 36 | 76·N | nodes, in list order (decreasing `r_max`) |
//! | 36 + 76·N | 8 | u64 FNV-1a 64 checksum of all bytes before it |
//!
//! A node record (76 bytes): f32×3 position (0), f32×3 normal (12), f32
//! diameter (24), f32 e_p (28), f32 e_t (32), f32 e_g (36), f32 r_min (40),
//! f32 r_max (44), u32 parent index (48; `0xFFFF_FFFF` for the root), u8×3
//! sRGB colour (52), u8 flags (55; bit 0 = leaf, other bits 0), u32 depth
//! (56), f32×4 clip lines (60; §10.2.4) as [`super::clip::ClipLines::packed`]
//! writes them: `θ0, c0, θ1, c1`, an absent line `c = f32::MAX`.
//!
//! Version 1 (still read, never written) is the same without the clip lines:
//! 60-byte node records, `36 + 60·N` then the checksum; its nodes get no clip
//! lines.
//!
//! Every value is finite: the root's `r_max` "∞" is stored as `f32::MAX`
//! ([`super::spt::ROOT_R_MAX`]). The reader checks, in this order: magic,
//! version (before the checksum, so that a file of a later version gets a
//! clear message even though its layout may differ), length against the node
//! count, checksum, then every value and the tree structure (one root, parent
//! indices in range, depth = parent's depth + 1 so there are no cycles,
//! leaves without children, inner nodes with children, sorted by decreasing
//! `r_max`, non-negative errors, `r_min ≤ r_max`, finite clip lines) and
//! magnitudes: coordinates within ±[`MAX_SPT_COORDINATE`] (10⁷ m), lengths
//! (bounds radius, diameters, errors, clip offsets, `r_min` and every
//! `r_max` but the root's) at most [`MAX_SPT_LENGTH`], every node's disk
//! inside the bounding sphere (a checksum proves only that the bytes were
//! not damaged, not that an edited file makes sense).

use std::path::Path;

use glam::Vec3;

use super::clip::{ClipLine, ClipLines};
use super::spt::{SequentialPointTree, SptNode};
use crate::error::{Error, Result};
use validate::validate;

mod validate;

/// The first eight bytes of every SPT file.
pub const SPT_MAGIC: [u8; 8] = *b"ALPSPT\0\0";
/// The version this build writes (it also reads [`SPT_VERSION_1`]).
pub const SPT_VERSION: u32 = 2;
/// The first version, without clip lines; read, never written.
pub const SPT_VERSION_1: u32 = 1;
/// Bytes before the first node.
pub const HEADER_BYTES: usize = 36;
/// Bytes per node record (version 2).
pub const NODE_BYTES: usize = 76;
/// Bytes per node record of version 1.
pub const NODE_BYTES_V1: usize = 60;
/// Bytes of the trailing checksum.
pub const CHECKSUM_BYTES: usize = 8;

/// Flag bit of a leaf node.
const FLAG_LEAF: u8 = 1;

/// FNV-1a, 64 bit.
fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// The file bytes of `tree` (assumed valid).
fn encode(tree: &SequentialPointTree) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_BYTES + NODE_BYTES * tree.nodes.len() + CHECKSUM_BYTES);
    out.extend_from_slice(&SPT_MAGIC);
    out.extend_from_slice(&SPT_VERSION.to_le_bytes());
    out.extend_from_slice(&(tree.nodes.len() as u32).to_le_bytes());
    let f = |out: &mut Vec<u8>, v: f32| out.extend_from_slice(&v.to_le_bytes());
    f(&mut out, tree.epsilon);
    for v in tree.bounds_centre.to_array() {
        f(&mut out, v);
    }
    f(&mut out, tree.bounds_radius);
    for node in &tree.nodes {
        for v in node.position.to_array() {
            f(&mut out, v);
        }
        for v in node.normal.to_array() {
            f(&mut out, v);
        }
        for v in [node.diameter, node.e_p, node.e_t, node.e_g, node.r_min, node.r_max] {
            f(&mut out, v);
        }
        out.extend_from_slice(&node.parent.to_le_bytes());
        out.extend_from_slice(&node.color);
        out.push(if node.is_leaf { FLAG_LEAF } else { 0 });
        out.extend_from_slice(&node.depth.to_le_bytes());
        for v in node.clip.packed() {
            f(&mut out, v);
        }
    }
    let checksum = fnv1a64(&out);
    out.extend_from_slice(&checksum.to_le_bytes());
    out
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    let mut b = [0u8; 4];
    b.copy_from_slice(&bytes[at..at + 4]);
    u32::from_le_bytes(b)
}

fn f32_at(bytes: &[u8], at: usize) -> f32 {
    f32::from_bits(u32_at(bytes, at))
}

fn vec3_at(bytes: &[u8], at: usize) -> Vec3 {
    Vec3::new(f32_at(bytes, at), f32_at(bytes, at + 4), f32_at(bytes, at + 8))
}

/// The clip lines of a packed `θ0, c0, θ1, c1` (inverse of
/// [`ClipLines::packed`]; `c = f32::MAX` is no line).
fn clip_lines_at(bytes: &[u8], at: usize) -> ClipLines {
    let line = |k: usize| {
        let offset = f32_at(bytes, at + 8 * k + 4);
        (offset != f32::MAX).then(|| ClipLine {
            angle: f32_at(bytes, at + 8 * k),
            offset,
        })
    };
    ClipLines([line(0), line(1)])
}

/// Parses file bytes; the message is one line without the file name.
fn decode(bytes: &[u8]) -> std::result::Result<SequentialPointTree, String> {
    let len = bytes.len();
    let magic_len = len.min(SPT_MAGIC.len());
    if bytes[..magic_len] != SPT_MAGIC[..magic_len] {
        return Err("not an alpenglow SPT file (wrong magic)".into());
    }
    if len < HEADER_BYTES {
        return Err(format!(
            "truncated: {len} bytes, shorter than the {HEADER_BYTES}-byte header"
        ));
    }
    let version = u32_at(bytes, 8);
    let node_bytes = match version {
        SPT_VERSION => NODE_BYTES,
        SPT_VERSION_1 => NODE_BYTES_V1,
        _ => {
            return Err(format!(
                "unsupported SPT version {version} (this build reads versions {SPT_VERSION_1} and {SPT_VERSION})"
            ))
        }
    };
    let count = u32_at(bytes, 12);
    let expected = HEADER_BYTES as u64 + node_bytes as u64 * u64::from(count) + CHECKSUM_BYTES as u64;
    if (len as u64) < expected {
        return Err(format!(
            "truncated or wrong node count: the header says {count} nodes ({expected} bytes), the file has {len} bytes"
        ));
    }
    if (len as u64) > expected {
        return Err(format!(
            "node count mismatch: the header says {count} nodes ({expected} bytes), the file has {len} bytes"
        ));
    }
    let body = len - CHECKSUM_BYTES;
    let mut stored = [0u8; 8];
    stored.copy_from_slice(&bytes[body..]);
    let stored = u64::from_le_bytes(stored);
    let computed = fnv1a64(&bytes[..body]);
    if stored != computed {
        return Err(format!(
            "checksum mismatch (stored {stored:016x}, computed {computed:016x}): the file is corrupt"
        ));
    }
    let mut nodes = Vec::with_capacity(count as usize);
    for i in 0..count as usize {
        let at = HEADER_BYTES + i * node_bytes;
        let flags = bytes[at + 55];
        if flags & !FLAG_LEAF != 0 {
            return Err(format!("node {i}: unknown flags {flags:#04x}"));
        }
        nodes.push(SptNode {
            position: vec3_at(bytes, at),
            normal: vec3_at(bytes, at + 12),
            diameter: f32_at(bytes, at + 24),
            e_p: f32_at(bytes, at + 28),
            e_t: f32_at(bytes, at + 32),
            e_g: f32_at(bytes, at + 36),
            r_min: f32_at(bytes, at + 40),
            r_max: f32_at(bytes, at + 44),
            parent: u32_at(bytes, at + 48),
            color: [bytes[at + 52], bytes[at + 53], bytes[at + 54]],
            is_leaf: flags & FLAG_LEAF != 0,
            depth: u32_at(bytes, at + 56),
            clip: if node_bytes == NODE_BYTES {
                clip_lines_at(bytes, at + 60)
            } else {
                ClipLines::NONE
            },
        });
    }
    let tree = SequentialPointTree {
        nodes,
        bounds_centre: vec3_at(bytes, 20),
        bounds_radius: f32_at(bytes, 32),
        epsilon: f32_at(bytes, 16),
    };
    validate(&tree)?;
    Ok(tree)
}

/// Writes `tree` to `path` in the format above, atomically (a failed write
/// leaves any existing file untouched).
///
/// Errors (one line, naming `path`): the tree is invalid (non-finite values,
/// broken structure: the same checks as [`read_spt`]), or the file cannot be
/// written.
pub fn write_spt(path: &Path, tree: &SequentialPointTree) -> Result<()> {
    validate(tree).map_err(|m| Error::output(path, format!("invalid sequential point tree: {m}")))?;
    crate::io::atomic::write_bytes_atomically(path, &encode(tree))
}

/// Reads a tree written by [`write_spt`].
///
/// Errors (one line, naming `path` and the problem): the file cannot be
/// read, wrong magic, unsupported version, truncated file or a node count
/// that does not match the length, checksum mismatch, non-finite or
/// out-of-range values, broken tree structure.
pub fn read_spt(path: &Path) -> Result<SequentialPointTree> {
    let bytes = crate::io::read_input(path)?;
    decode(&bytes).map_err(|m| Error::input(path, m))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::points::build::spt::{build_spt, SptOptions};
    use crate::points::Surfel;
    use std::path::PathBuf;

    fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("alpenglow-spt-file-{}-{}", std::process::id(), name));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn tree() -> SequentialPointTree {
        let mut surfels = Vec::new();
        for i in 0..12 {
            for j in 0..9 {
                let (x, y) = (i as f32 * 0.5, j as f32 * 0.5);
                surfels.push(Surfel {
                    position: Vec3::new(x, y, (x * 0.7).sin() * (y * 0.3).cos()),
                    normal: Vec3::new(-0.2 * x.cos(), 0.1, 1.0).normalize(),
                    radius: 0.35,
                    color: [(i * 20) as u8, (j * 25) as u8, 77],
                    // A few surfels with one or two clip lines.
                    clip: match (i + j) % 5 {
                        0 => ClipLines([
                            Some(ClipLine {
                                angle: 0.5,
                                offset: 0.1,
                            }),
                            None,
                        ]),
                        1 => ClipLines([
                            Some(ClipLine {
                                angle: -2.0,
                                offset: -0.05,
                            }),
                            Some(ClipLine {
                                angle: 3.0,
                                offset: 0.2,
                            }),
                        ]),
                        _ => ClipLines::NONE,
                    },
                });
            }
        }
        build_spt(&surfels, &SptOptions::default(), &mut |_| {}).unwrap()
    }

    /// Recomputes the checksum after a deliberate edit of the body.
    fn reseal(bytes: &mut [u8]) {
        let body = bytes.len() - CHECKSUM_BYTES;
        let c = fnv1a64(&bytes[..body]);
        bytes[body..].copy_from_slice(&c.to_le_bytes());
    }

    fn read_err(path: &Path, bytes: &[u8]) -> String {
        std::fs::write(path, bytes).unwrap();
        let err = read_spt(path).unwrap_err().to_string();
        assert!(err.contains(&*path.to_string_lossy()), "{err}");
        assert!(!err.contains('\n'), "{err}");
        err
    }

    #[test]
    fn fnv1a64_reference_values() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
    }

    #[test]
    fn round_trip_is_exact() {
        let dir = scratch_dir("round");
        let path = dir.join("t.spt");
        let t = tree();
        write_spt(&path, &t).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes.len(), HEADER_BYTES + NODE_BYTES * t.nodes.len() + CHECKSUM_BYTES);
        assert_eq!(&bytes[..8], b"ALPSPT\0\0");
        let back = read_spt(&path).unwrap();
        assert_eq!(back, t);
        // Overwriting goes through the atomic writer and leaves no temporaries.
        write_spt(&path, &back).unwrap();
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The version 1 bytes of `tree` (60-byte records without clip lines),
    /// as earlier builds wrote them.
    fn encode_v1(tree: &SequentialPointTree) -> Vec<u8> {
        let v2 = encode(tree);
        let mut out = v2[..HEADER_BYTES].to_vec();
        out[8..12].copy_from_slice(&1u32.to_le_bytes());
        for i in 0..tree.nodes.len() {
            let at = HEADER_BYTES + i * NODE_BYTES;
            out.extend_from_slice(&v2[at..at + NODE_BYTES_V1]);
        }
        out.extend_from_slice(&[0; CHECKSUM_BYTES]);
        reseal(&mut out);
        out
    }

    #[test]
    fn clip_lines_round_trip_and_version_1_still_reads() {
        let dir = scratch_dir("v1");
        let path = dir.join("t.spt");
        let t = tree();
        let clipped = t.nodes.iter().filter(|n| n.clip != ClipLines::NONE).count();
        assert!(clipped > 10 && t.nodes.iter().all(|n| n.is_leaf || n.clip == ClipLines::NONE));
        write_spt(&path, &t).unwrap();
        assert_eq!(u32_at(&std::fs::read(&path).unwrap(), 8), 2);
        assert_eq!(read_spt(&path).unwrap(), t);

        let v1 = encode_v1(&t);
        assert_eq!(v1.len(), HEADER_BYTES + NODE_BYTES_V1 * t.nodes.len() + CHECKSUM_BYTES);
        std::fs::write(&path, &v1).unwrap();
        let back = read_spt(&path).unwrap();
        let mut expected = t.clone();
        for n in &mut expected.nodes {
            n.clip = ClipLines::NONE;
        }
        assert_eq!(back, expected);
        // Version 1 errors are still the same one-line messages.
        let err = read_err(&path, &v1[..v1.len() - 3]);
        assert!(err.contains("truncated"), "{err}");
        let mut b = v1.clone();
        b[HEADER_BYTES + 3] ^= 1;
        assert!(read_err(&path, &b).contains("checksum mismatch"));
        // A version 2 body labelled version 1 does not fit the length.
        let mut b = encode(&t);
        b[8..12].copy_from_slice(&1u32.to_le_bytes());
        reseal(&mut b);
        assert!(read_err(&path, &b).contains("node count mismatch"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn corruption_is_detected() {
        let dir = scratch_dir("corrupt");
        let path = dir.join("c.spt");
        let good = encode(&tree());
        let len = good.len();

        // Any flipped byte after the header fields checked before the
        // checksum is a checksum mismatch.
        for at in [
            13,
            16,
            20,
            32,
            HEADER_BYTES,
            HEADER_BYTES + 7,
            len / 2,
            len - 9,
            len - 1,
        ] {
            let mut b = good.clone();
            b[at] ^= 0x40;
            let err = read_err(&path, &b);
            let expected = if at < 16 { "node count" } else { "checksum mismatch" };
            assert!(err.contains(expected), "byte {at}: {err}");
        }
        // Magic.
        let mut b = good.clone();
        b[0] = b'X';
        assert!(read_err(&path, &b).contains("wrong magic"));
        assert!(read_err(&path, b"PNG\x89 not an spt file at all").contains("wrong magic"));
        // Future version (with a valid checksum, so the version is the message).
        let mut b = good.clone();
        b[8..12].copy_from_slice(&3u32.to_le_bytes());
        reseal(&mut b);
        assert!(read_err(&path, &b).contains("unsupported SPT version 3"));
        // Truncation anywhere.
        for cut in [0, 5, 8, 20, HEADER_BYTES, HEADER_BYTES + 30, len - 1] {
            let err = read_err(&path, &good[..cut]);
            assert!(err.contains("truncated"), "cut {cut}: {err}");
        }
        // Count mismatch: too few nodes claimed (trailing bytes), too many.
        let mut b = good.clone();
        let count = u32_at(&b, 12);
        b[12..16].copy_from_slice(&(count - 1).to_le_bytes());
        assert!(read_err(&path, &b).contains("node count mismatch"));
        b[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(read_err(&path, &b).contains("truncated or wrong node count"));
        // Appended garbage.
        let mut b = good.clone();
        b.extend_from_slice(&[0; 3]);
        assert!(read_err(&path, &b).contains("node count mismatch"));
        // Missing file, directory.
        assert!(read_spt(&dir.join("missing.spt"))
            .unwrap_err()
            .to_string()
            .contains("not found"));
        assert!(read_spt(&dir).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn invalid_values_are_rejected_even_with_a_valid_checksum() {
        let dir = scratch_dir("values");
        let path = dir.join("v.spt");
        let good = encode(&tree());
        let node1 = HEADER_BYTES + NODE_BYTES;
        let cases: Vec<(usize, Vec<u8>, &str)> = vec![
            (16, f32::NAN.to_le_bytes().to_vec(), "epsilon"),
            (20, f32::INFINITY.to_le_bytes().to_vec(), "bounds centre"),
            (node1, f32::NAN.to_le_bytes().to_vec(), "node 1: non-finite position"),
            (node1 + 12, f32::NAN.to_le_bytes().to_vec(), "node 1: non-finite normal"),
            (
                node1 + 24,
                f32::INFINITY.to_le_bytes().to_vec(),
                "node 1: non-finite diameter",
            ),
            (node1 + 36, (-1.0f32).to_le_bytes().to_vec(), "node 1: negative e_g"),
            (
                HEADER_BYTES + 44,
                f32::INFINITY.to_le_bytes().to_vec(),
                "node 0: non-finite r_max",
            ),
            (node1 + 48, 9_999_999u32.to_le_bytes().to_vec(), "node 1: parent index"),
            (node1 + 55, vec![0x82], "node 1: unknown flags"),
            (node1 + 56, 77u32.to_le_bytes().to_vec(), "node 1: depth"),
            (HEADER_BYTES + 48, 1u32.to_le_bytes().to_vec(), "node 0"),
            (
                node1 + 64,
                f32::NAN.to_le_bytes().to_vec(),
                "node 1: non-finite clip line",
            ),
            (
                node1 + 72,
                f32::INFINITY.to_le_bytes().to_vec(),
                "node 1: non-finite clip line",
            ),
        ];
        for (at, patch, expected) in cases {
            let mut b = good.clone();
            b[at..at + patch.len()].copy_from_slice(&patch);
            reseal(&mut b);
            let err = read_err(&path, &b);
            assert!(err.contains(expected), "patch at {at}: {err}");
        }
        // Zero nodes.
        let mut b = good[..HEADER_BYTES].to_vec();
        b[12..16].copy_from_slice(&0u32.to_le_bytes());
        b.extend_from_slice(&[0; CHECKSUM_BYTES]);
        reseal(&mut b);
        assert!(read_err(&path, &b).contains("no nodes"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn absurd_values_with_a_recomputed_checksum_are_rejected() {
        let dir = scratch_dir("absurd");
        let path = dir.join("a.spt");
        let t = tree();
        let good = encode(&t);
        let leaf = t
            .nodes
            .iter()
            .position(|n| n.is_leaf && n.clip != ClipLines::NONE)
            .unwrap();
        let at = HEADER_BYTES + NODE_BYTES * leaf;
        let node1 = HEADER_BYTES + NODE_BYTES;
        let huge = 3e38f32.to_le_bytes().to_vec();
        let cases: Vec<(usize, Vec<u8>, String)> = vec![
            (20, huge.clone(), "bounds centre (3e38, ".into()),
            (28, (-2e7f32).to_le_bytes().to_vec(), "exceeds ±10000000 m".into()),
            (32, huge.clone(), "bounds radius 3e38".into()),
            // The sphere no longer holds the disks.
            (32, 1e-3f32.to_le_bytes().to_vec(), "outside the bounds radius".into()),
            (node1 + 4, huge.clone(), "node 1: position".into()),
            (node1 + 24, huge.clone(), "node 1: diameter 3e38 exceeds".into()),
            (
                node1 + 28,
                5e7f32.to_le_bytes().to_vec(),
                "node 1: e_p 5e7 exceeds".into(),
            ),
            (at + 64, huge.clone(), format!("node {leaf}: clip line 0")),
            (
                at + 60,
                1e30f32.to_le_bytes().to_vec(),
                format!("node {leaf}: clip line 0"),
            ),
            (
                node1 + 44,
                f32::MAX.to_le_bytes().to_vec(),
                "node 1: r_max is the root's".into(),
            ),
        ];
        for (offset, patch, expected) in cases {
            let mut b = good.clone();
            b[offset..offset + patch.len()].copy_from_slice(&patch);
            reseal(&mut b);
            let err = read_err(&path, &b);
            assert!(err.contains(&expected), "patch at {offset}: {err}");
        }
        // An inner node whose children are re-parented to the root.
        let mut t2 = t.clone();
        let inner = (1..t2.nodes.len()).find(|&i| !t2.nodes[i].is_leaf).unwrap();
        for node in t2.nodes.iter_mut().filter(|n| n.parent == inner as u32) {
            node.parent = 0;
            node.depth = 1;
        }
        let mut b = encode(&t2);
        reseal(&mut b);
        let err = read_err(&path, &b);
        assert!(err.contains("without children") || err.contains("depth"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn writing_an_invalid_tree_is_an_error_and_writes_nothing() {
        let dir = scratch_dir("write");
        let path = dir.join("w.spt");
        let mut t = tree();
        t.nodes[3].e_t = f32::NAN;
        let err = write_spt(&path, &t).unwrap_err().to_string();
        assert!(err.contains("w.spt") && err.contains("node 3: non-finite e_t"), "{err}");
        assert!(!path.exists());
        let mut t = tree();
        t.nodes.swap(0, 5);
        assert!(write_spt(&path, &t).is_err());
        assert!(write_spt(&dir.join("no/such/dir.spt"), &tree()).is_err());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
