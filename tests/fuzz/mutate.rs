//! Mutations of seed files, driven by `arbitrary::Unstructured` (so arbtest
//! replays and minimises them from a seed): bit flips, interesting bytes and
//! words, inserts, deletes, truncation, duplication, splicing two seeds and,
//! for text, number and token replacement.

use arbitrary::{Result, Unstructured};

/// Bytes worth trying at any offset.
const BYTES: [u8; 12] = [0x00, 0xff, 0x7f, 0x80, 0x01, b'0', b'9', b'-', b'.', b'\n', b' ', b'e'];

/// 32-bit words worth trying (counts, sizes, float bit patterns).
const WORDS: [u32; 12] = [
    0,
    1,
    u32::MAX,
    0x7fff_ffff,
    0x8000_0000,
    0xffff,
    0x1_0000,
    0x7fc0_0000, // f32 NaN
    0x7f80_0000, // f32 +inf
    0xff80_0000, // f32 −inf
    0x7f7f_ffff, // f32::MAX
    0x4b18_9680, // 1e7 as f32
];

/// Numbers worth writing into text.
const NUMBERS: [&str; 20] = [
    "0",
    "-0",
    "-1",
    "1e308",
    "-1e308",
    "1e309",
    "3e38",
    "1e-45",
    "nan",
    "inf",
    "-inf",
    "NaN",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "99999999999999999999999",
    "2147483648",
    "1e7",
    "0.5",
    "65536",
];

/// How a seed is mutated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Binary format: byte and word mutations.
    Binary,
    /// Text format: byte mutations plus number and token replacement.
    Text,
}

fn index(u: &mut Unstructured, len: usize) -> Result<usize> {
    if len == 0 {
        return Ok(0);
    }
    u.choose_index(len)
}

/// Replaces the `k`-th whitespace- or punctuation-separated token of `text`
/// with `with`.
fn replace_token(bytes: &mut Vec<u8>, u: &mut Unstructured, with: &[u8]) -> Result<()> {
    let is_sep = |b: u8| b.is_ascii_whitespace() || b"[],={}\"#".contains(&b);
    let starts: Vec<usize> = (0..bytes.len())
        .filter(|&i| !is_sep(bytes[i]) && (i == 0 || is_sep(bytes[i - 1])))
        .collect();
    if starts.is_empty() {
        return Ok(());
    }
    let start = starts[index(u, starts.len())?];
    let end = (start..bytes.len()).find(|&i| is_sep(bytes[i])).unwrap_or(bytes.len());
    bytes.splice(start..end, with.iter().copied());
    Ok(())
}

/// Any token of `text` (to duplicate keywords and names elsewhere).
fn some_token(bytes: &[u8], u: &mut Unstructured) -> Result<Vec<u8>> {
    let tokens: Vec<&[u8]> = bytes
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
        .collect();
    if tokens.is_empty() {
        return Ok(b"x".to_vec());
    }
    Ok(tokens[index(u, tokens.len())?].to_vec())
}

/// One mutation of `bytes`; `other` is a second seed for splicing.
fn mutate_once(bytes: &mut Vec<u8>, other: &[u8], kind: Kind, u: &mut Unstructured) -> Result<()> {
    let len = bytes.len();
    let ops = if kind == Kind::Text { 12 } else { 10 };
    match u.choose_index(ops)? {
        0 if len > 0 => {
            let i = index(u, len)?;
            bytes[i] ^= 1 << u.int_in_range(0..=7)?;
        }
        1 if len > 0 => {
            let i = index(u, len)?;
            bytes[i] = if u.arbitrary()? {
                *u.choose(&BYTES)?
            } else {
                u.arbitrary()?
            };
        }
        2 if len >= 4 => {
            let i = index(u, len - 3)?;
            let w = *u.choose(&WORDS)?;
            let le: bool = u.arbitrary()?;
            bytes[i..i + 4].copy_from_slice(&if le { w.to_le_bytes() } else { w.to_be_bytes() });
        }
        3 => {
            let i = index(u, len + 1)?;
            let n = u.int_in_range(1..=16)?;
            let fill: Vec<u8> = (0..n).map(|_| u.choose(&BYTES).copied()).collect::<Result<_>>()?;
            bytes.splice(i..i, fill);
        }
        4 if len > 0 => {
            let i = index(u, len)?;
            let n = u.int_in_range(1..=32.min(len - i))?;
            bytes.drain(i..i + n);
        }
        5 => {
            let keep = index(u, len + 1)?;
            bytes.truncate(keep);
        }
        6 if len > 0 => {
            // Duplicate a chunk (repeated records, lines, chunks).
            let i = index(u, len)?;
            let n = u.int_in_range(1..=64.min(len - i))?;
            let chunk = bytes[i..i + n].to_vec();
            let at = index(u, len + 1)?;
            bytes.splice(at..at, chunk);
        }
        7 => {
            // Splice: a prefix of this seed and a suffix of the other.
            let a = index(u, len + 1)?;
            let b = index(u, other.len() + 1)?;
            bytes.truncate(a);
            bytes.extend_from_slice(&other[b..]);
        }
        8 if len > 0 => {
            let i = index(u, len)?;
            let n = u.int_in_range(1..=8.min(len - i))?;
            for b in &mut bytes[i..i + n] {
                *b = u.arbitrary()?;
            }
        }
        9 if len >= 8 => {
            let i = index(u, len - 7)?;
            let v: f64 = *u.choose(&[f64::NAN, f64::INFINITY, -1e308, 1e300, 0.0, -1.0])?;
            bytes[i..i + 8].copy_from_slice(&v.to_le_bytes());
        }
        10 => {
            let number = u.choose(&NUMBERS)?.as_bytes().to_vec();
            replace_token(bytes, u, &number)?;
        }
        11 => {
            let token = some_token(bytes, u)?;
            replace_token(bytes, u, &token)?;
        }
        _ => {}
    }
    Ok(())
}

/// A mutated copy of one of `seeds` (1 to 8 mutations, sometimes none).
pub fn mutate(seeds: &[Vec<u8>], kind: Kind, u: &mut Unstructured) -> Result<Vec<u8>> {
    let mut bytes = u.choose(seeds)?.clone();
    let other = u.choose(seeds)?.clone();
    let count = u.int_in_range(0..=8)?;
    for _ in 0..count {
        mutate_once(&mut bytes, &other, kind, u)?;
        if bytes.len() > 1 << 20 {
            bytes.truncate(1 << 20);
        }
    }
    Ok(bytes)
}

/// FNV-1a 64, the SPT checksum.
fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Rewrites an SPT file's trailing checksum so that mutations reach the
/// value checks behind it.
pub fn reseal_spt(bytes: &mut [u8]) {
    if bytes.len() >= 16 {
        let body = bytes.len() - 8;
        let c = fnv1a64(&bytes[..body]);
        bytes[body..].copy_from_slice(&c.to_le_bytes());
    }
}

/// CRC-32 (IEEE), as PNG chunks use.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = u32::MAX;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// Recomputes the CRC of every complete PNG chunk so that mutations reach
/// the decoder behind the checks (header sizes, zlib data).
pub fn fix_png_crcs(bytes: &mut [u8]) {
    let mut at = 8;
    while at + 12 <= bytes.len() {
        let len = u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]) as usize;
        let Some(end) = (at + 8).checked_add(len) else { return };
        if end + 4 > bytes.len() {
            return;
        }
        let crc = crc32(&bytes[at + 4..end]);
        bytes[end..end + 4].copy_from_slice(&crc.to_be_bytes());
        at = end + 4;
    }
}
