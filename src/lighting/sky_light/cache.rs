//! The sky-light bake cache: one file per (height field, settings) under a
//! directory the caller chooses, written atomically ([`crate::io::atomic`]).
//!
//! Layout (little endian): magic `ALPGSKYL`, format version (u32), the key
//! ([`BakeKey`]: SH bands, bounces, azimuths, bounce albedo bits, columns,
//! rows as u32, then the height field's content hash as u64), the byte
//! lengths of the three payloads (u64 each: surface, transfer, horizon
//! map), the payloads, and a 64-bit checksum of everything before it.
//!
//! A file that is truncated, corrupt (checksum), of another format version
//! or of another key is rebuilt; one that cannot be read (permissions, a
//! directory of that name) or written is an error naming it, which the
//! bake ([`super::SkyLightBake::bake`]) turns into a warning: the cache is
//! optional. Never wrong lighting: the key and the checksum are checked
//! before any use.

use std::io::{BufWriter, ErrorKind, Write};
use std::path::{Path, PathBuf};

use super::bake::BakeSettings;
use crate::error::{Error, Result};
use crate::io::atomic::write_atomically;
use crate::io::heightmap::HeightField;

const MAGIC: &[u8; 8] = b"ALPGSKYL";
/// Bumped whenever the bake's algorithm or layout changes.
pub const FORMAT_VERSION: u32 = 2;
/// The largest cache file read (a 4097² field with 5 bands and its horizon
/// maps is about 8 GiB; larger files are rebuilt, not read).
const MAX_CACHE_BYTES: u64 = 8 << 30;

const HEADER_BYTES: usize = 8 + 4 + 6 * 4 + 8 + 3 * 8;

/// What a bake depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BakeKey {
    pub sh_bands: u32,
    pub bounces: u32,
    pub azimuths: u32,
    pub bounce_albedo_bits: u32,
    pub columns: u32,
    pub rows: u32,
    /// [`field_hash`] of the height field.
    pub field_hash: u64,
}

impl BakeKey {
    /// The key of baking `field` with `settings`.
    pub fn new(field: &HeightField, settings: &BakeSettings) -> BakeKey {
        BakeKey {
            sh_bands: settings.sh_bands,
            bounces: settings.bounces,
            azimuths: settings.azimuths,
            bounce_albedo_bits: settings.bounce_albedo.to_bits(),
            columns: field.columns,
            rows: field.rows,
            field_hash: field_hash(field),
        }
    }

    fn bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(32);
        for v in [
            self.sh_bands,
            self.bounces,
            self.azimuths,
            self.bounce_albedo_bits,
            self.columns,
            self.rows,
        ] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&self.field_hash.to_le_bytes());
        b
    }
}

/// A bake on the host: the GPU buffers' bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BakeData {
    pub key: BakeKey,
    /// Per texel 8 f32: normal, sky visibility, bent normal, 0.
    pub surface: Vec<u8>,
    /// Per texel `stride` f32: SH transfer, then 8×8 patch transfer.
    pub transfer: Vec<u8>,
    /// The horizon map's texels (RGBA32F, 2·columns × 2·rows).
    pub horizon: Vec<u8>,
}

/// A 64-bit FNV-1a variant over 8-byte words (the tail zero-padded); the
/// same for any split of the input into `update` calls.
#[derive(Clone, Copy)]
struct Hasher {
    state: u64,
    pending: [u8; 8],
    filled: usize,
}

impl Hasher {
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    fn new() -> Hasher {
        Hasher {
            state: 0xcbf2_9ce4_8422_2325,
            pending: [0; 8],
            filled: 0,
        }
    }

    fn word(&mut self, w: [u8; 8]) {
        self.state = (self.state ^ u64::from_le_bytes(w)).wrapping_mul(Self::PRIME);
    }

    fn update(&mut self, mut bytes: &[u8]) {
        if self.filled > 0 {
            let take = (8 - self.filled).min(bytes.len());
            self.pending[self.filled..self.filled + take].copy_from_slice(&bytes[..take]);
            self.filled += take;
            bytes = &bytes[take..];
            if self.filled < 8 {
                return;
            }
            self.word(self.pending);
            self.filled = 0;
        }
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            let mut a = [0u8; 8];
            a.copy_from_slice(w);
            self.word(a);
        }
        let rest = words.remainder();
        self.pending[..rest.len()].copy_from_slice(rest);
        self.filled = rest.len();
    }

    fn finish(mut self) -> u64 {
        if self.filled > 0 {
            let mut last = [0u8; 8];
            last[..self.filled].copy_from_slice(&self.pending[..self.filled]);
            self.word(last);
            // The length of the tail, so zero padding is not ambiguous.
            self.state = (self.state ^ self.filled as u64).wrapping_mul(Self::PRIME);
        }
        // A final avalanche so nearby inputs differ in every bit.
        let mut h = self.state;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^ (h >> 33)
    }
}

/// Content hash of a height field: size, spacing and every sample.
pub fn field_hash(field: &HeightField) -> u64 {
    let mut h = Hasher::new();
    h.update(&field.columns.to_le_bytes());
    h.update(&field.rows.to_le_bytes());
    h.update(&field.spacing.x.to_le_bytes());
    h.update(&field.spacing.y.to_le_bytes());
    h.update(bytemuck::cast_slice(&field.heights));
    h.finish()
}

/// The cache file of `key` in `dir`.
pub fn cache_path(dir: &Path, key: &BakeKey) -> PathBuf {
    let mut h = Hasher::new();
    h.update(&key.bytes());
    dir.join(format!("sky-light-{:016x}.bin", h.finish()))
}

/// Why a file is rebuilt.
fn parse(bytes: &[u8], key: &BakeKey) -> std::result::Result<BakeData, String> {
    if bytes.len() < HEADER_BYTES + 8 {
        return Err(format!("truncated ({} bytes)", bytes.len()));
    }
    if &bytes[..8] != MAGIC {
        return Err("not a sky-light cache file".into());
    }
    let body = &bytes[..bytes.len() - 8];
    let mut h = Hasher::new();
    h.update(body);
    let u32_at = |o: usize| u32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    let u64_at = |o: usize| u64::from(u32_at(o)) | (u64::from(u32_at(o + 4)) << 32);
    if u64_at(bytes.len() - 8) != h.finish() {
        return Err("checksum mismatch (corrupt or truncated)".into());
    }
    let version = u32_at(8);
    if version != FORMAT_VERSION {
        return Err(format!("format version {version}, expected {FORMAT_VERSION}"));
    }
    if bytes[12..44] != key.bytes()[..] {
        return Err("stale (another height field or settings)".into());
    }
    let lengths = [u64_at(44), u64_at(52), u64_at(60)];
    let total = lengths.iter().try_fold(0u64, |sum, &l| sum.checked_add(l));
    if total != Some(body.len() as u64 - HEADER_BYTES as u64) {
        return Err("payload lengths do not match the file size".into());
    }
    let (a, b) = (HEADER_BYTES, HEADER_BYTES + lengths[0] as usize);
    let c = b + lengths[1] as usize;
    Ok(BakeData {
        key: *key,
        surface: body[a..b].to_vec(),
        transfer: body[b..c].to_vec(),
        horizon: body[c..].to_vec(),
    })
}

/// The cached bake at `path` if it is valid for `key`; `None` when there is
/// none or it must be rebuilt (logged). Errors: the file exists but cannot
/// be read.
pub fn load(path: &Path, key: &BakeKey) -> Result<Option<BakeData>> {
    // Checked before opening: a FIFO would block, a device never end.
    // No file there (also when a folder on the way is a file: storing
    // will say so).
    let absent = |e: &std::io::Error| matches!(e.kind(), ErrorKind::NotFound | ErrorKind::NotADirectory);
    match std::fs::metadata(path) {
        Err(e) if absent(&e) => return Ok(None),
        Ok(meta) if !meta.is_file() => return Err(Error::input(path, "the sky-light cache is not a regular file")),
        Ok(meta) if meta.len() > MAX_CACHE_BYTES => {
            log::warn!(
                "{}: sky-light cache of {} bytes is too large; rebuilding",
                path.display(),
                meta.len()
            );
            return Ok(None);
        }
        _ => {}
    }
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if absent(&e) => return Ok(None),
        Err(e) => {
            return Err(Error::input(
                path,
                format!("cannot read the sky-light cache: {}", crate::io::one_line(e)),
            ))
        }
    };
    match parse(&bytes, key) {
        Ok(data) => Ok(Some(data)),
        Err(why) => {
            log::warn!("{}: sky-light cache {why}; rebuilding", path.display());
            Ok(None)
        }
    }
}

/// Writes `data` to `path` atomically, creating its directory.
pub fn store(path: &Path, data: &BakeData) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| {
            Error::output(
                path,
                format!(
                    "cannot create the cache directory {}: {}",
                    dir.display(),
                    crate::io::one_line(e)
                ),
            )
        })?;
    }
    let mut header = Vec::with_capacity(HEADER_BYTES);
    header.extend_from_slice(MAGIC);
    header.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    header.extend_from_slice(&data.key.bytes());
    for len in [data.surface.len(), data.transfer.len(), data.horizon.len()] {
        header.extend_from_slice(&(len as u64).to_le_bytes());
    }
    write_atomically(path, |tmp| {
        let io = |e: std::io::Error| Error::output(path, crate::io::one_line(e));
        let file = std::fs::File::create(tmp).map_err(io)?;
        let mut out = BufWriter::new(file);
        let mut h = Hasher::new();
        for part in [&header[..], &data.surface, &data.transfer, &data.horizon] {
            h.update(part);
            out.write_all(part).map_err(io)?;
        }
        out.write_all(&h.finish().to_le_bytes()).map_err(io)?;
        out.into_inner().map_err(|e| io(e.into_error()))?.sync_all().map_err(io)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn sample() -> (BakeData, BakeKey) {
        let field = HeightField::from_fn(3, 2, DVec2::ONE, |c, r| (c + r) as f32);
        let key = BakeKey::new(&field, &BakeSettings::default());
        let data = BakeData {
            key,
            surface: vec![1; 24],
            transfer: vec![2; 40],
            horizon: vec![3; 16],
        };
        (data, key)
    }

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("alpenglow-sky-cache-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn round_trip_and_every_kind_of_damage() {
        let dir = temp_dir("unit");
        let (data, key) = sample();
        let path = cache_path(&dir, &key);
        assert!(load(&path, &key).unwrap().is_none(), "missing: rebuild");
        store(&path, &data).unwrap();
        assert_eq!(load(&path, &key).unwrap().as_ref(), Some(&data));
        let bytes = std::fs::read(&path).unwrap();
        // Truncated.
        std::fs::write(&path, &bytes[..bytes.len() - 5]).unwrap();
        assert!(load(&path, &key).unwrap().is_none());
        // One flipped payload bit.
        let mut corrupt = bytes.clone();
        corrupt[HEADER_BYTES + 3] ^= 1;
        std::fs::write(&path, &corrupt).unwrap();
        assert!(load(&path, &key).unwrap().is_none());
        // Another key (stale).
        std::fs::write(&path, &bytes).unwrap();
        let other = BakeKey { bounces: 2, ..key };
        assert!(load(&path, &other).unwrap().is_none());
        // A directory where the file should be: an error naming it.
        std::fs::remove_file(&path).unwrap();
        std::fs::create_dir_all(&path).unwrap();
        let e = load(&path, &key).unwrap_err().to_string();
        assert!(e.contains(&path.display().to_string()) && !e.contains('\n'), "{e}");
        let e = store(&path, &data).unwrap_err().to_string();
        assert!(e.contains(&path.display().to_string()) && !e.contains('\n'), "{e}");
        // A FIFO is refused before opening (reading it would block).
        std::fs::remove_dir_all(&path).unwrap();
        let made = std::process::Command::new("mkfifo").arg(&path).status();
        if made.is_ok_and(|s| s.success()) {
            let e = load(&path, &key).unwrap_err().to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Payload lengths whose sum overflows u64 (behind a valid checksum) are
    /// a rebuild, not an arithmetic overflow.
    #[test]
    fn overflowing_lengths_are_rebuilt() {
        let dir = temp_dir("overflow");
        let (data, key) = sample();
        let path = cache_path(&dir, &key);
        store(&path, &data).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        for o in [44, 52] {
            bytes[o..o + 8].copy_from_slice(&(u64::MAX / 2 + 1).to_le_bytes());
        }
        let body = bytes.len() - 8;
        let mut h = Hasher::new();
        h.update(&bytes[..body]);
        let sum = h.finish().to_le_bytes();
        bytes[body..].copy_from_slice(&sum);
        std::fs::write(&path, &bytes).unwrap();
        assert!(load(&path, &key).unwrap().is_none());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_checksum_does_not_depend_on_how_the_input_is_split() {
        let data: Vec<u8> = (0..100u8).collect();
        let mut whole = Hasher::new();
        whole.update(&data);
        let mut parts = Hasher::new();
        for part in [&data[..3], &data[3..20], &data[20..21], &data[21..]] {
            parts.update(part);
        }
        assert_eq!(whole.finish(), parts.finish());
    }

    #[test]
    fn the_field_hash_sees_every_sample_and_the_spacing() {
        let a = HeightField::from_fn(4, 4, DVec2::ONE, |c, r| (c * r) as f32);
        let mut b = a.clone();
        b.heights[7] += 1e-3;
        let mut c = a.clone();
        c.spacing.x = 1.5;
        assert_ne!(field_hash(&a), field_hash(&b));
        assert_ne!(field_hash(&a), field_hash(&c));
        assert_eq!(field_hash(&a), field_hash(&a.clone()));
    }
}
