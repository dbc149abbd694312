//! The bytes of a height pyramid file (`.hpyr`): the header and the tile
//! index; [`super`] describes the layout in prose.
//!
//! The tile codec (quantised heights, planar prediction, zig-zag varints,
//! deflate) and the level filter live in the workspace crate
//! `alpenglow-height-codec`, compiled optimised in every build. Smooth
//! terrain leaves residuals of a byte or less, so a tile of real relief
//! takes 1–2 bytes a sample and a smooth one a small fraction of that. The
//! CRC-32 of the deflated bytes sits in the index, so a corrupt tile is
//! found before it is inflated.

/// First bytes of every pyramid file.
pub(crate) const MAGIC: [u8; 8] = *b"ALPGHPYR";
/// The format version this build writes and reads.
pub(crate) const VERSION: u32 = 1;
/// Bytes of the fixed header.
pub(crate) const HEADER_BYTES: usize = 96;
/// Bytes of one tile's index entry.
pub(crate) const ENTRY_BYTES: usize = 24;
/// Most levels a pyramid can have (a 2³¹-sample side needs 24 of 256²
/// tiles).
pub(crate) const MAX_LEVELS: u32 = 32;

/// The fixed header: what the pyramid holds and where its index is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Header {
    pub tile_side: u32,
    pub columns: u32,
    pub rows: u32,
    pub spacing: [f64; 2],
    pub height_step: f64,
    pub levels: u32,
    pub min_height: f32,
    pub max_height: f32,
    pub index_offset: u64,
    pub index_entries: u64,
    pub index_crc: u32,
}

impl Header {
    pub fn encode(&self) -> [u8; HEADER_BYTES] {
        let mut b = [0u8; HEADER_BYTES];
        b[0..8].copy_from_slice(&MAGIC);
        b[8..12].copy_from_slice(&VERSION.to_le_bytes());
        b[12..16].copy_from_slice(&self.tile_side.to_le_bytes());
        b[16..20].copy_from_slice(&self.columns.to_le_bytes());
        b[20..24].copy_from_slice(&self.rows.to_le_bytes());
        b[24..32].copy_from_slice(&self.spacing[0].to_le_bytes());
        b[32..40].copy_from_slice(&self.spacing[1].to_le_bytes());
        b[40..48].copy_from_slice(&self.height_step.to_le_bytes());
        b[48..52].copy_from_slice(&self.levels.to_le_bytes());
        b[56..60].copy_from_slice(&self.min_height.to_le_bytes());
        b[60..64].copy_from_slice(&self.max_height.to_le_bytes());
        b[64..72].copy_from_slice(&self.index_offset.to_le_bytes());
        b[72..80].copy_from_slice(&self.index_entries.to_le_bytes());
        b[80..84].copy_from_slice(&self.index_crc.to_le_bytes());
        let crc = crc32fast::hash(&b[..92]);
        b[92..96].copy_from_slice(&crc.to_le_bytes());
        b
    }

    /// The header of `b`, or why it is not one (magic, version, checksum).
    pub fn decode(b: &[u8]) -> Result<Header, String> {
        if b.len() < HEADER_BYTES || b[0..8] != MAGIC {
            return Err("not an alpenglow height pyramid (bad magic bytes)".into());
        }
        let u32_at = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap_or_default());
        let u64_at = |o: usize| u64::from_le_bytes(b[o..o + 8].try_into().unwrap_or_default());
        let f64_at = |o: usize| f64::from_le_bytes(b[o..o + 8].try_into().unwrap_or_default());
        let f32_at = |o: usize| f32::from_le_bytes(b[o..o + 4].try_into().unwrap_or_default());
        let version = u32_at(8);
        if version != VERSION {
            return Err(format!(
                "pyramid format version {version}; this build reads version {VERSION}"
            ));
        }
        if crc32fast::hash(&b[..92]) != u32_at(92) {
            return Err("the header's checksum does not match (corrupt file)".into());
        }
        Ok(Header {
            tile_side: u32_at(12),
            columns: u32_at(16),
            rows: u32_at(20),
            spacing: [f64_at(24), f64_at(32)],
            height_step: f64_at(40),
            levels: u32_at(48),
            min_height: f32_at(56),
            max_height: f32_at(60),
            index_offset: u64_at(64),
            index_entries: u64_at(72),
            index_crc: u32_at(80),
        })
    }
}

/// Where one tile's bytes are, their checksum and the tile's height range.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct TileEntry {
    pub offset: u64,
    pub length: u32,
    pub crc: u32,
    pub min: f32,
    pub max: f32,
}

impl TileEntry {
    pub fn encode_into(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.offset.to_le_bytes());
        out.extend_from_slice(&self.length.to_le_bytes());
        out.extend_from_slice(&self.crc.to_le_bytes());
        out.extend_from_slice(&self.min.to_le_bytes());
        out.extend_from_slice(&self.max.to_le_bytes());
    }

    pub fn decode(b: &[u8]) -> TileEntry {
        let u32_at = |o: usize| u32::from_le_bytes(b[o..o + 4].try_into().unwrap_or_default());
        TileEntry {
            offset: u64::from_le_bytes(b[0..8].try_into().unwrap_or_default()),
            length: u32_at(8),
            crc: u32_at(12),
            min: f32::from_bits(u32_at(16)),
            max: f32::from_bits(u32_at(20)),
        }
    }
}

/// Samples per side of each level: level 0 is the field; level `l + 1`
/// keeps every second sample of level `l` (`⌈(n − 1) / 2⌉ + 1`), down to
/// the first level that fits one tile.
pub(crate) fn level_sizes(columns: u32, rows: u32, tile_side: u32) -> Vec<(u32, u32)> {
    let mut sizes = vec![(columns, rows)];
    let mut size = (columns, rows);
    while (size.0 > tile_side || size.1 > tile_side) && sizes.len() < MAX_LEVELS as usize {
        size = ((size.0 - 1).div_ceil(2) + 1, (size.1 - 1).div_ceil(2) + 1);
        sizes.push(size);
    }
    sizes
}

pub(crate) use alpenglow_height_codec::{decode_tile, downsample_row, encode_tile, first_out_of_range};
