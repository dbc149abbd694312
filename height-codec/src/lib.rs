//! The per-sample work of alpenglow's height pyramids (`.hpyr`,
//! `alpenglow::files::HeightPyramid`): the tile codec and the filter that
//! makes each coarser level. A crate of its own so that it is compiled
//! optimised in every build (see the workspace's `Cargo.toml`): a pyramid
//! of a real region passes 10⁹–10¹⁰ samples through these loops.
//!
//! # Tile codec
//!
//! Heights quantised to multiples of the file's height step
//! (`q = round(h / step)`), each sample predicted from its left, upper and
//! upper-left neighbours (`left + up − up_left`, the planar predictor of
//! lossless image coders; the first row and column predict from their one
//! neighbour, the first sample from 0), the residuals zig-zag coded as
//! LEB128 varints and the stream deflated. Smooth terrain leaves residuals
//! of a byte or less.

#![forbid(unsafe_code)]

use std::io::{Read, Write};

use flate2::read::DeflateDecoder;
use flate2::write::DeflateEncoder;
use flate2::Compression;

/// The deflated code of a tile of `samples` (`width` per row) and the
/// height range of its quantised samples.
pub fn encode_tile(samples: &[f32], width: usize, step: f64) -> (Vec<u8>, f32, f32) {
    let inverse = 1.0 / step;
    let quantised: Vec<i64> = samples
        .iter()
        .map(|&h| (f64::from(h) * inverse).round() as i64)
        .collect();
    let lo = quantised.iter().copied().min().unwrap_or(0);
    let hi = quantised.iter().copied().max().unwrap_or(0);
    let mut stream = Vec::with_capacity(samples.len() + samples.len() / 2);
    let mut push = |residual: i64| {
        let mut zigzag = ((residual << 1) ^ (residual >> 63)) as u64;
        while zigzag >= 0x80 {
            stream.push((zigzag as u8) | 0x80);
            zigzag >>= 7;
        }
        stream.push(zigzag as u8);
    };
    for (r, row) in quantised.chunks(width.max(1)).enumerate() {
        if r == 0 {
            let mut left = 0i64;
            for &q in row {
                push(q.wrapping_sub(left));
                left = q;
            }
            continue;
        }
        let up = &quantised[(r - 1) * width..r * width];
        push(row[0].wrapping_sub(up[0]));
        for c in 1..row.len() {
            let predicted = row[c - 1].wrapping_add(up[c]).wrapping_sub(up[c - 1]);
            push(row[c].wrapping_sub(predicted));
        }
    }
    let mut encoder = DeflateEncoder::new(Vec::with_capacity(stream.len() / 4 + 64), Compression::fast());
    // Writing into a Vec cannot fail.
    let _ = encoder.write_all(&stream);
    let bytes = encoder.finish().unwrap_or_default();
    (bytes, (lo as f64 * step) as f32, (hi as f64 * step) as f32)
}

/// The `width × height` heights of a tile's code, or why it is not one.
pub fn decode_tile(bytes: &[u8], width: usize, height: usize, step: f64) -> Result<Vec<f32>, String> {
    let count = width * height;
    // A varint of a 64-bit residual takes at most 10 bytes.
    let limit = (count * 10) as u64;
    let mut stream = Vec::with_capacity(count + count / 2);
    DeflateDecoder::new(bytes)
        .take(limit + 1)
        .read_to_end(&mut stream)
        .map_err(|e| format!("the tile does not inflate ({e})"))?;
    if stream.len() as u64 > limit {
        return Err("the tile inflates to more bytes than its samples can take".into());
    }
    let mut residuals = Vec::with_capacity(count);
    let mut at = 0usize;
    while residuals.len() < count {
        let mut value = 0u64;
        let mut shift = 0u32;
        loop {
            let Some(&byte) = stream.get(at) else {
                return Err(format!("the tile ends after {} of {count} samples", residuals.len()));
            };
            at += 1;
            if shift > 63 {
                return Err("a residual of the tile is longer than 64 bits".into());
            }
            value |= u64::from(byte & 0x7f) << shift;
            shift += 7;
            if byte & 0x80 == 0 {
                break;
            }
        }
        residuals.push((value >> 1) as i64 ^ -((value & 1) as i64));
    }
    if at != stream.len() {
        return Err(format!("{} bytes follow the tile's samples", stream.len() - at));
    }
    let mut q = vec![0i64; count];
    for r in 0..height {
        for c in 0..width {
            let i = r * width + c;
            let predicted = match (c, r) {
                (0, 0) => 0,
                (_, 0) => q[i - 1],
                (0, _) => q[i - width],
                _ => q[i - 1].wrapping_add(q[i - width]).wrapping_sub(q[i - width - 1]),
            };
            q[i] = predicted.wrapping_add(residuals[i]);
        }
    }
    Ok(q.iter().map(|&v| (v as f64 * step) as f32).collect())
}

/// One row of the next coarser level from three rows of a level (rows
/// `2r − 1, 2r, 2r + 1`, clamped by the caller): the `[1 2 1] / 4`
/// binomial filter each way centred on every second sample, columns
/// clamped at the edges. `out` has `⌈(n − 1) / 2⌉ + 1` samples for rows
/// of `n`.
pub fn downsample_row(rows: [&[f32]; 3], out: &mut [f32]) {
    let n = rows[0].len();
    if n == 0 || rows[1].len() != n || rows[2].len() != n {
        out.fill(0.0);
        return;
    }
    let vertical = |x: usize| rows[0][x] + 2.0 * rows[1][x] + rows[2][x];
    for (c, value) in out.iter_mut().enumerate() {
        let centre = (2 * c).min(n - 1);
        let left = (2 * c).saturating_sub(1).min(n - 1);
        let right = (2 * c + 1).min(n - 1);
        *value = (vertical(left) + 2.0 * vertical(centre) + vertical(right)) / 16.0;
    }
}

/// The index of the first sample that is not finite or exceeds `max_abs`
/// in magnitude.
pub fn first_out_of_range(samples: &[f32], max_abs: f32) -> Option<usize> {
    samples.iter().position(|h| !(h.is_finite() && h.abs() <= max_abs))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_within_half_a_step() {
        let samples: Vec<f32> = (0..37 * 11)
            .map(|i| ((i * 7919) % 1000) as f32 * 1.37 - 400.0)
            .collect();
        let step = 1.0 / 256.0;
        let (bytes, lo, hi) = encode_tile(&samples, 37, step);
        let back = decode_tile(&bytes, 37, 11, step).unwrap();
        for (a, b) in samples.iter().zip(&back) {
            assert!((a - b).abs() <= 0.5 / 256.0 + 1e-4, "{a} {b}");
        }
        assert!(lo <= -399.0 && hi >= 900.0);
        assert!(decode_tile(&bytes, 37, 12, step).is_err());
        assert!(decode_tile(&bytes[..bytes.len() / 2], 37, 11, step).is_err());
    }

    #[test]
    fn filter_weights_sum_to_one_and_clamp() {
        let rows = [[1.0f32; 5], [1.0; 5], [1.0; 5]];
        let mut out = [0.0f32; 3];
        downsample_row([&rows[0], &rows[1], &rows[2]], &mut out);
        assert_eq!(out, [1.0; 3]);
        let ramp = [0.0f32, 1.0, 2.0, 3.0, 4.0, 5.0];
        let mut out = [0.0f32; 4];
        downsample_row([&ramp, &ramp, &ramp], &mut out);
        // Centres 0, 2, 4, 6 → 5 (every index clamped): (0+0+1)/4,
        // (1+4+3)/4, (3+8+5)/4, (5+10+5)/4.
        assert_eq!(out, [0.25, 2.0, 4.0, 5.0]);
    }
}
