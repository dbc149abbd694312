//! Writing a height pyramid in one pass over the field's rows
//! ([`write_pyramid`]): the source is read a band of `tile_side` rows at a
//! time, every level keeps one band of its own rows (plus the last three
//! for the next level's filter), and a band's tiles are encoded on every
//! core and appended to the file as soon as the band is full. The index
//! follows the tiles and the header is written last; the file appears
//! under its name only when it is complete ([`write_atomically`]).
//!
//! Host memory: about `tile_side × columns × 4 B` for level 0 and half as
//! much for each coarser level, `≈ 2 · tile_side · columns · 4 B` in all
//! (128 MiB for a 65536-sample-wide field), whatever the number of rows.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::Path;

use glam::DVec2;

use super::format::{self, Header, TileEntry, ENTRY_BYTES, HEADER_BYTES};
use super::{HeightRows, PyramidOptions, PyramidSummary};
use crate::error::{Error, Result};
use crate::io::atomic::write_atomically;
use crate::io::heightmap::{check_spacing, MAX_ABS_HEIGHT};

/// Writes the pyramid of `source` to `path` (all or nothing).
pub fn write_pyramid(path: &Path, source: &mut dyn HeightRows, options: &PyramidOptions) -> Result<PyramidSummary> {
    options.validate()?;
    let shape = source.shape().clone();
    let (columns, rows) = (shape.columns, shape.rows);
    if columns < 2 || rows < 2 {
        return Err(Error::input(
            &shape.origin,
            format!("height field is {columns}×{rows}; at least 2×2 samples are needed"),
        ));
    }
    check_spacing(shape.spacing).map_err(|m| Error::input(&shape.origin, m))?;
    let mut summary = None;
    write_atomically(path, |tmp| {
        let file = File::create(tmp).map_err(|e| write_error(path, e))?;
        let mut writer = PyramidBuilder::new(path, BufWriter::with_capacity(1 << 20, file), columns, rows, options);
        writer
            .out
            .write_all(&[0u8; HEADER_BYTES])
            .map_err(|e| write_error(path, e))?;
        writer.offset = HEADER_BYTES as u64;
        let band = options.tile_side;
        let mut buffer = vec![0f32; band as usize * columns as usize];
        let mut first = 0u32;
        while first < rows {
            let count = band.min(rows - first);
            let slice = &mut buffer[..count as usize * columns as usize];
            source.read_rows(first, slice)?;
            check_heights(&shape.origin, slice, columns, first)?;
            for row in slice.chunks_exact(columns as usize) {
                writer.accept(0, row.to_vec())?;
            }
            first += count;
        }
        summary = Some(writer.finish(shape.spacing)?);
        Ok(())
    })?;
    summary.ok_or_else(|| Error::output(path, "the pyramid was not written"))
}

fn write_error(path: &Path, e: std::io::Error) -> Error {
    Error::output(path, format!("writing the pyramid failed: {}", crate::io::one_line(e)))
}

/// Every height of `rows` (starting at field row `first`) finite and within
/// ±[`MAX_ABS_HEIGHT`].
fn check_heights(origin: &Path, rows: &[f32], columns: u32, first: u32) -> Result<()> {
    match format::first_out_of_range(rows, MAX_ABS_HEIGHT) {
        None => Ok(()),
        Some(i) => Err(Error::input(
            origin,
            format!(
                "height at column {}, row {} is {} m; heights must be finite and within ±{} km",
                i % columns as usize,
                first as usize + i / columns as usize,
                rows[i],
                MAX_ABS_HEIGHT / 1000.0
            ),
        )),
    }
}

/// One level being built: its current band of rows and the last rows the
/// next level's filter needs.
struct LevelBuilder {
    columns: u32,
    rows: u32,
    tiles_x: u32,
    band: Vec<f32>,
    band_rows: u32,
    received: u32,
    recent: VecDeque<(u32, Vec<f32>)>,
    emitted: u32,
    entries: Vec<TileEntry>,
}

struct PyramidBuilder<'p, W: Write + Seek> {
    path: &'p Path,
    out: W,
    offset: u64,
    tile_side: u32,
    step: f64,
    levels: Vec<LevelBuilder>,
    min: f32,
    max: f32,
}

impl<'p, W: Write + Seek> PyramidBuilder<'p, W> {
    fn new(path: &'p Path, out: W, columns: u32, rows: u32, options: &PyramidOptions) -> Self {
        let t = options.tile_side;
        let levels = format::level_sizes(columns, rows, t)
            .into_iter()
            .map(|(c, r)| LevelBuilder {
                columns: c,
                rows: r,
                tiles_x: c.div_ceil(t),
                band: Vec::with_capacity(t as usize * c as usize),
                band_rows: 0,
                received: 0,
                recent: VecDeque::with_capacity(3),
                emitted: 0,
                entries: vec![TileEntry::default(); (c.div_ceil(t) * r.div_ceil(t)) as usize],
            })
            .collect();
        PyramidBuilder {
            path,
            out,
            offset: 0,
            tile_side: t,
            step: options.height_step,
            levels,
            min: f32::INFINITY,
            max: f32::NEG_INFINITY,
        }
    }

    /// Row `received` of level `l` arrives.
    fn accept(&mut self, l: usize, row: Vec<f32>) -> Result<()> {
        let t = self.tile_side;
        let level = &mut self.levels[l];
        level.band.extend_from_slice(&row);
        level.band_rows += 1;
        let k = level.received;
        level.received += 1;
        if level.band_rows == t || level.received == level.rows {
            self.flush_band(l)?;
        }
        if l + 1 == self.levels.len() {
            return Ok(());
        }
        let level = &mut self.levels[l];
        if level.recent.len() == 3 {
            level.recent.pop_front();
        }
        level.recent.push_back((k, row));
        let last = level.rows - 1;
        let next_rows = self.levels[l + 1].rows;
        loop {
            let level = &mut self.levels[l];
            let r = level.emitted;
            if r >= next_rows || (2 * r + 1).min(last) > k {
                return Ok(());
            }
            level.emitted += 1;
            let coarse = downsample_row(level, r, last);
            self.accept(l + 1, coarse)?;
        }
    }

    /// Encodes the band of level `l` as tiles (on every core), appends them.
    fn flush_band(&mut self, l: usize) -> Result<()> {
        let t = self.tile_side as usize;
        let level = &mut self.levels[l];
        let (columns, band_rows) = (level.columns as usize, level.band_rows as usize);
        let ty = (level.received as usize - 1) / t;
        let tiles: Vec<(usize, usize)> = (0..level.tiles_x as usize)
            .map(|tx| (tx * t, (columns - tx * t).min(t)))
            .collect();
        let band = &level.band;
        let step = self.step;
        let encode = |&(c0, width): &(usize, usize)| {
            let mut samples = Vec::with_capacity(width * band_rows);
            for r in 0..band_rows {
                samples.extend_from_slice(&band[r * columns + c0..r * columns + c0 + width]);
            }
            format::encode_tile(&samples, width, step)
        };
        let encoded = parallel_map(&tiles, encode);
        for (tx, (bytes, lo, hi)) in encoded.into_iter().enumerate() {
            self.out.write_all(&bytes).map_err(|e| write_error(self.path, e))?;
            let length = u32::try_from(bytes.len()).map_err(|_| Error::output(self.path, "a tile exceeds 4 GiB"))?;
            level.entries[ty * level.tiles_x as usize + tx] = TileEntry {
                offset: self.offset,
                length,
                crc: crc32fast::hash(&bytes),
                min: lo,
                max: hi,
            };
            self.offset += bytes.len() as u64;
            if l == 0 {
                self.min = self.min.min(lo);
                self.max = self.max.max(hi);
            }
        }
        level.band.clear();
        level.band_rows = 0;
        Ok(())
    }

    /// Writes the index and the header.
    fn finish(mut self, spacing: DVec2) -> Result<PyramidSummary> {
        let mut index = Vec::new();
        for level in &self.levels {
            for entry in &level.entries {
                entry.encode_into(&mut index);
            }
        }
        let entries = (index.len() / ENTRY_BYTES) as u64;
        let header = Header {
            tile_side: self.tile_side,
            columns: self.levels[0].columns,
            rows: self.levels[0].rows,
            spacing: [spacing.x, spacing.y],
            height_step: self.step,
            levels: self.levels.len() as u32,
            min_height: self.min,
            max_height: self.max,
            index_offset: self.offset,
            index_entries: entries,
            index_crc: crc32fast::hash(&index),
        };
        let io = |e| write_error(self.path, e);
        self.out.write_all(&index).map_err(io)?;
        self.out.seek(SeekFrom::Start(0)).map_err(io)?;
        self.out.write_all(&header.encode()).map_err(io)?;
        self.out.flush().map_err(io)?;
        Ok(PyramidSummary {
            columns: header.columns,
            rows: header.rows,
            levels: header.levels,
            tiles: entries,
            bytes: self.offset + index.len() as u64,
            min_height: self.min,
            max_height: self.max,
        })
    }
}

/// Row `r` of the next level from the level's rows `2r − 1, 2r, 2r + 1`
/// (clamped at the edges; [`format::downsample_row`]: a `[1 2 1] / 4`
/// binomial low-pass each way before dropping every second sample).
fn downsample_row(level: &LevelBuilder, r: u32, last: u32) -> Vec<f32> {
    let row = |k: i64| -> &[f32] {
        let k = k.clamp(0, i64::from(last)) as u32;
        level
            .recent
            .iter()
            .find(|(index, _)| *index == k)
            .map(|(_, row)| row.as_slice())
            // The three rows `2r − 1 ..= 2r + 1` (clamped) are always recent.
            .unwrap_or(&[])
    };
    let r = i64::from(r);
    let mut out = vec![0f32; ((level.columns - 1).div_ceil(2) + 1) as usize];
    format::downsample_row([row(2 * r - 1), row(2 * r), row(2 * r + 1)], &mut out);
    out
}

/// `f` of every item, on up to every core (std threads; order kept).
pub(crate) fn parallel_map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len().max(1));
    if threads <= 1 {
        return items.iter().map(&f).collect();
    }
    let chunk = items.len().div_ceil(threads);
    std::thread::scope(|scope| {
        let handles: Vec<_> = items
            .chunks(chunk)
            .map(|part| scope.spawn(|| part.iter().map(&f).collect::<Vec<R>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}
