//! Reading a height pyramid: [`HeightPyramid::open`] reads and checks the
//! header and the tile index (a few MiB even for 10¹⁰ samples); tiles are
//! read on demand, each checked against its CRC-32 before it is inflated.

use std::fs::File;
use std::path::{Path, PathBuf};

use glam::DVec2;

use super::format::{self, Header, TileEntry, ENTRY_BYTES, HEADER_BYTES, MAX_LEVELS};
use super::{PyramidTile, TileKey};
use crate::error::{Error, Result};
use crate::io::heightmap::{check_spacing, HeightField, MAX_ABS_HEIGHT};

/// A height pyramid file opened for reading.
#[derive(Debug)]
pub struct HeightPyramid {
    path: PathBuf,
    file: File,
    header: Header,
    /// Samples per side of each level.
    sizes: Vec<(u32, u32)>,
    /// Index of each level's first entry in `entries`.
    first_entry: Vec<usize>,
    entries: Vec<TileEntry>,
}

impl HeightPyramid {
    /// Opens `path` and checks its header and index; one-line errors name
    /// the file.
    pub fn open(path: &Path) -> Result<HeightPyramid> {
        let bad = |m: String| Error::input(path, m);
        let file = File::open(path).map_err(|e| bad(format!("cannot open: {}", crate::io::one_line(e))))?;
        let length = file.metadata().map_err(|e| bad(crate::io::one_line(e)))?.len();
        let mut head = [0u8; HEADER_BYTES];
        if length < HEADER_BYTES as u64 {
            return Err(bad(format!("{length} bytes: too short for a height pyramid")));
        }
        read_at(&file, 0, &mut head).map_err(|e| bad(format!("reading the header failed: {e}")))?;
        let header = Header::decode(&head).map_err(bad)?;
        let sizes = check_header(&header).map_err(bad)?;
        let tiles: u64 = sizes
            .iter()
            .map(|&(c, r)| u64::from(c.div_ceil(header.tile_side)) * u64::from(r.div_ceil(header.tile_side)))
            .sum();
        if tiles != header.index_entries {
            return Err(bad(format!(
                "the index has {} entries; the levels need {tiles}",
                header.index_entries
            )));
        }
        let index_bytes = tiles * ENTRY_BYTES as u64;
        if header.index_offset < HEADER_BYTES as u64 || header.index_offset.checked_add(index_bytes) != Some(length) {
            return Err(bad(format!(
                "the index ({index_bytes} bytes at {}) does not end the {length}-byte file (truncated?)",
                header.index_offset
            )));
        }
        let mut index = vec![0u8; index_bytes as usize];
        read_at(&file, header.index_offset, &mut index).map_err(|e| bad(format!("reading the index failed: {e}")))?;
        if crc32fast::hash(&index) != header.index_crc {
            return Err(bad("the tile index's checksum does not match (corrupt file)".into()));
        }
        let entries: Vec<TileEntry> = index.chunks_exact(ENTRY_BYTES).map(TileEntry::decode).collect();
        let max_tile = 10 * u64::from(header.tile_side).pow(2) + 1024;
        for (i, e) in entries.iter().enumerate() {
            let inside = e.offset >= HEADER_BYTES as u64
                && e.offset
                    .checked_add(u64::from(e.length))
                    .is_some_and(|end| end <= header.index_offset);
            if !inside || u64::from(e.length) > max_tile || !matches!(e.min.partial_cmp(&e.max), Some(o) if o.is_le()) {
                return Err(bad(format!("tile entry {i} of the index is invalid")));
            }
        }
        let mut first_entry = Vec::with_capacity(sizes.len());
        let mut at = 0usize;
        for &(c, r) in &sizes {
            first_entry.push(at);
            at += (c.div_ceil(header.tile_side) * r.div_ceil(header.tile_side)) as usize;
        }
        Ok(HeightPyramid {
            path: path.to_path_buf(),
            file,
            header,
            sizes,
            first_entry,
            entries,
        })
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Samples per side of level 0 (the field).
    pub fn size(&self) -> (u32, u32) {
        self.sizes[0]
    }

    /// Number of levels (level 0 is the field, the last fits one tile).
    pub fn levels(&self) -> u32 {
        self.sizes.len() as u32
    }

    /// Samples per side of level `level`.
    pub fn level_size(&self, level: u32) -> (u32, u32) {
        self.sizes[(level as usize).min(self.sizes.len() - 1)]
    }

    /// Samples per tile side.
    pub fn tile_side(&self) -> u32 {
        self.header.tile_side
    }

    /// Tiles of level `level` along x and y.
    pub fn tiles(&self, level: u32) -> (u32, u32) {
        let (c, r) = self.level_size(level);
        (c.div_ceil(self.header.tile_side), r.div_ceil(self.header.tile_side))
    }

    /// Metres between level-0 samples.
    pub fn spacing(&self) -> DVec2 {
        DVec2::from(self.header.spacing)
    }

    /// Size of the covered area in metres (as [`HeightField::extent`]).
    pub fn extent(&self) -> DVec2 {
        let (c, r) = self.size();
        DVec2::new(f64::from(c - 1), f64::from(r - 1)) * self.spacing()
    }

    /// Metres between the samples of level `level` as it is placed over the
    /// field's extent: level `l` sample `c` sits at `c · extent / (n_l − 1)`
    /// (the level's own step `2^l · spacing`, stretched by less than one of
    /// its samples when `n_0 − 1` is not a multiple of `2^l`).
    pub fn level_spacing(&self, level: u32) -> DVec2 {
        let (c, r) = self.level_size(level);
        self.extent() / DVec2::new(f64::from(c - 1), f64::from(r - 1))
    }

    /// Smallest and largest height of the field (quantised).
    pub fn height_range(&self) -> (f32, f32) {
        (self.header.min_height, self.header.max_height)
    }

    /// Height quantum of the file (metres).
    pub fn height_step(&self) -> f64 {
        self.header.height_step
    }

    /// Height range of one tile, from the index (no read).
    pub fn tile_range(&self, key: TileKey) -> Option<(f32, f32)> {
        self.entry(key).map(|e| (e.min, e.max))
    }

    /// Bytes of the file.
    pub fn file_bytes(&self) -> u64 {
        self.header.index_offset + self.entries.len() as u64 * ENTRY_BYTES as u64
    }

    /// The finest level whose longer side has at most `max_side` samples
    /// (the coarsest level if none does).
    pub fn level_within(&self, max_side: u32) -> u32 {
        self.sizes
            .iter()
            .position(|&(c, r)| c.max(r) <= max_side)
            .unwrap_or(self.sizes.len() - 1) as u32
    }

    fn entry(&self, key: TileKey) -> Option<&TileEntry> {
        let level = key.level as usize;
        let (tx, ty) = self.tiles(key.level);
        if level >= self.sizes.len() || key.x >= tx || key.y >= ty {
            return None;
        }
        self.entries
            .get(self.first_entry[level] + (key.y * tx + key.x) as usize)
    }

    /// Reads and decodes one tile; a missing key or a corrupt tile is an
    /// error naming the file and the tile.
    pub fn read_tile(&self, key: TileKey) -> Result<PyramidTile> {
        let bad = |m: String| Error::input(&self.path, format!("tile {key}: {m}"));
        let entry = *self.entry(key).ok_or_else(|| bad("no such tile".into()))?;
        let mut bytes = vec![0u8; entry.length as usize];
        read_at(&self.file, entry.offset, &mut bytes).map_err(|e| bad(format!("reading failed: {e}")))?;
        if crc32fast::hash(&bytes) != entry.crc {
            return Err(bad("its checksum does not match (corrupt file)".into()));
        }
        let t = self.header.tile_side;
        let (c, r) = self.level_size(key.level);
        let (width, height) = ((c - key.x * t).min(t), (r - key.y * t).min(t));
        let heights =
            format::decode_tile(&bytes, width as usize, height as usize, self.header.height_step).map_err(bad)?;
        Ok(PyramidTile {
            key,
            width,
            height,
            heights,
        })
    }

    /// Samples `[c0, c0 + width) × [r0, r0 + height)` of level `level`,
    /// row-major, read tile by tile (coordinates past the level's edge
    /// repeat its edge samples).
    pub fn read_region(&self, level: u32, c0: u32, r0: u32, width: u32, height: u32) -> Result<Vec<f32>> {
        let t = self.header.tile_side;
        let (columns, rows) = self.level_size(level);
        let mut out = vec![0f32; width as usize * height as usize];
        let clamp_c = |c: u32| c.min(columns - 1);
        let clamp_r = |r: u32| r.min(rows - 1);
        let (tx0, tx1) = (clamp_c(c0) / t, clamp_c(c0.saturating_add(width - 1)) / t);
        let (ty0, ty1) = (clamp_r(r0) / t, clamp_r(r0.saturating_add(height - 1)) / t);
        // The output rows (columns) that fall in each tile row (column).
        let rows_in = |ty: u32| -> Vec<(usize, usize)> {
            (r0..r0 + height)
                .enumerate()
                .filter(|&(_, r)| clamp_r(r) / t == ty)
                .map(|(j, r)| (j, (clamp_r(r) - ty * t) as usize))
                .collect()
        };
        let columns_in: Vec<Vec<(usize, usize)>> = (tx0..=tx1)
            .map(|tx| {
                (c0..c0 + width)
                    .enumerate()
                    .filter(|&(_, c)| clamp_c(c) / t == tx)
                    .map(|(i, c)| (i, (clamp_c(c) - tx * t) as usize))
                    .collect()
            })
            .collect();
        for ty in ty0..=ty1 {
            let rows_here = rows_in(ty);
            for (tx, columns_here) in (tx0..=tx1).zip(&columns_in) {
                let tile = self.read_tile(TileKey { level, x: tx, y: ty })?;
                for &(j, tr) in &rows_here {
                    let src = &tile.heights[tr * tile.width as usize..(tr + 1) * tile.width as usize];
                    let dst = &mut out[j * width as usize..(j + 1) * width as usize];
                    for &(i, tc) in columns_here {
                        dst[i] = src[tc];
                    }
                }
            }
        }
        Ok(out)
    }

    /// The whole of level `level` as a height field over the field's
    /// extent ([`HeightPyramid::level_spacing`]).
    pub fn level_field(&self, level: u32) -> Result<HeightField> {
        let (columns, rows) = self.level_size(level);
        Ok(HeightField {
            columns,
            rows,
            spacing: self.level_spacing(level),
            heights: self.read_region(level, 0, 0, columns, rows)?,
        })
    }

    /// Reads and decodes every tile (a full check of the file).
    pub fn verify(&self) -> Result<()> {
        for level in 0..self.levels() {
            let (tx, ty) = self.tiles(level);
            for y in 0..ty {
                for x in 0..tx {
                    self.read_tile(TileKey { level, x, y })?;
                }
            }
        }
        Ok(())
    }
}

/// The level sizes of a header, or why it is not a sane one.
fn check_header(h: &Header) -> std::result::Result<Vec<(u32, u32)>, String> {
    if !(super::MIN_TILE_SIDE..=super::MAX_TILE_SIDE).contains(&h.tile_side) {
        return Err(format!("tile side {} is out of range", h.tile_side));
    }
    if h.columns < 2 || h.rows < 2 {
        return Err(format!("{}×{} samples; at least 2×2 are needed", h.columns, h.rows));
    }
    check_spacing(DVec2::from(h.spacing))?;
    if !(super::MIN_HEIGHT_STEP..=super::MAX_HEIGHT_STEP).contains(&h.height_step) {
        return Err(format!("height step {} m is out of range", h.height_step));
    }
    let finite = |v: f32| v.is_finite() && v.abs() <= MAX_ABS_HEIGHT;
    if !(finite(h.min_height) && finite(h.max_height) && h.min_height <= h.max_height) {
        return Err("the height range in the header is invalid".into());
    }
    let sizes = format::level_sizes(h.columns, h.rows, h.tile_side);
    if h.levels != sizes.len() as u32 || h.levels > MAX_LEVELS {
        return Err(format!("{} levels; a field of this size has {}", h.levels, sizes.len()));
    }
    Ok(sizes)
}

/// Fills `buf` from `offset` of `file` (positioned read: no shared cursor,
/// so several threads may read one file).
fn read_at(file: &File, offset: u64, buf: &mut [u8]) -> std::result::Result<(), String> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileExt;
        file.read_exact_at(buf, offset).map_err(crate::io::one_line)
    }
    #[cfg(windows)]
    {
        use std::os::windows::fs::FileExt;
        let mut done = 0usize;
        while done < buf.len() {
            let n = file
                .seek_read(&mut buf[done..], offset + done as u64)
                .map_err(crate::io::one_line)?;
            if n == 0 {
                return Err("unexpected end of file".into());
            }
            done += n;
        }
        Ok(())
    }
}
