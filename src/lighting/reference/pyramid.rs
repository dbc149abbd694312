//! The height field as the GPU ray tracer reads it (§9.2;
//! `glsl/include/heightfield_trace.glsl`, `HeightfieldData`): one storage
//! buffer of 32-bit words, a header of `MAX_LEVELS + 2` uvec4 rows, then the
//! heights and a max-mip pyramid of the cells.
//!
//! * header row 0: columns, rows, pyramid levels, 0;
//! * header row 1: f32 bits of the lowest and highest height, 0, 0;
//! * header row 2 + L: level L's offset (in floats after the header), its
//!   width and height in nodes, 0;
//! * the heights, row-major, from float 0;
//! * level 0: per cell (columns−1 × rows−1), the highest of its four
//!   corners (the bilinear patch never rises above it); level L+1: per node,
//!   the highest of the 2×2 level-L nodes it covers, until 1×1.

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;

/// Pyramid levels at most (fields up to 32768 cells per side).
pub const MAX_LEVELS: usize = 16;
/// Header words.
const HEADER_WORDS: usize = 4 * (MAX_LEVELS + 2);

/// The words of the GPU height-field buffer of `field` (validated by the
/// caller).
pub fn field_buffer_words(field: &HeightField) -> Result<Vec<u32>> {
    super::validate_field(field)?;
    let (w, h) = (field.columns as usize, field.rows as usize);
    let mut levels: Vec<(usize, usize, Vec<f32>)> = Vec::new();
    let mut level0 = Vec::with_capacity((w - 1) * (h - 1));
    for r in 0..h - 1 {
        for c in 0..w - 1 {
            let at = |c: usize, r: usize| field.heights[r * w + c];
            level0.push(at(c, r).max(at(c + 1, r)).max(at(c, r + 1)).max(at(c + 1, r + 1)));
        }
    }
    levels.push((w - 1, h - 1, level0));
    while let Some((lw, lh, prev)) = levels.last() {
        let (lw, lh) = (*lw, *lh);
        if lw == 1 && lh == 1 {
            break;
        }
        let (nw, nh) = (lw.div_ceil(2), lh.div_ceil(2));
        let mut next = Vec::with_capacity(nw * nh);
        for r in 0..nh {
            for c in 0..nw {
                let mut m = f32::NEG_INFINITY;
                for (dc, dr) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (pc, pr) = (2 * c + dc, 2 * r + dr);
                    if pc < lw && pr < lh {
                        m = m.max(prev[pr * lw + pc]);
                    }
                }
                next.push(m);
            }
        }
        levels.push((nw, nh, next));
    }
    if levels.len() > MAX_LEVELS {
        return Err(Error::invalid(
            "lighting.reference.height_field",
            format!("{w}×{h} samples; at most 32769 per side"),
        ));
    }
    let (lo, hi) = field.min_max();
    let mut words = vec![0u32; HEADER_WORDS];
    words[..4].copy_from_slice(&[field.columns, field.rows, levels.len() as u32, 0]);
    words[4] = lo.to_bits();
    words[5] = hi.to_bits();
    words.extend(field.heights.iter().map(|v| v.to_bits()));
    for (l, (lw, lh, values)) in levels.iter().enumerate() {
        let offset = (words.len() - HEADER_WORDS) as u32;
        words[4 * (2 + l)..4 * (3 + l)].copy_from_slice(&[offset, *lw as u32, *lh as u32, 0]);
        words.extend(values.iter().map(|v| v.to_bits()));
    }
    Ok(words)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    #[test]
    fn levels_shrink_to_one_node_holding_the_maximum() {
        let f = HeightField::from_fn(6, 4, DVec2::ONE, |c, r| (c * 3 + r * 7 % 5) as f32);
        let words = field_buffer_words(&f).unwrap();
        let levels = words[2] as usize;
        // Cells 5×3 → 3×2 → 2×1 → 1×1.
        assert_eq!(levels, 4);
        let row = |l: usize| &words[4 * (2 + l)..4 * (3 + l)];
        assert_eq!(&row(0)[1..3], &[5, 3]);
        assert_eq!(&row(3)[1..3], &[1, 1]);
        let top = f32::from_bits(words[HEADER_WORDS + row(3)[0] as usize]);
        assert_eq!(top, f.min_max().1);
        assert_eq!(f32::from_bits(words[HEADER_WORDS]), f.heights[0]);
        // Cell (1, 1) of level 0: its four corners' maximum.
        let cell = f32::from_bits(words[HEADER_WORDS + row(0)[0] as usize + 5 + 1]);
        let at = |c: usize, r: usize| f.heights[r * 6 + c];
        assert_eq!(cell, at(1, 1).max(at(2, 1)).max(at(1, 2)).max(at(2, 2)));
    }

    #[test]
    fn bad_fields_are_errors() {
        let mut f = HeightField::from_fn(4, 4, DVec2::ONE, |_, _| 0.0);
        f.heights[3] = f32::NAN;
        assert!(field_buffer_words(&f).is_err());
        let f = HeightField::from_fn(1, 4, DVec2::ONE, |_, _| 0.0);
        assert!(field_buffer_words(&f).is_err());
    }
}
