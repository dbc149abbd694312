//! Streaming detail near the camera (issue 31 item 1; §7.4.4: "a large
//! sketch atlas in main memory and only the visible part in video
//! memory"): over the resident level of a height pyramid
//! (`Scene::from_pyramid`) a **detail window** of a finer level follows
//! the camera.
//!
//! * **Which level.** The finest level finer than the resident one whose
//!   window (`side` samples a side) spans at least [`GROUND_PER_EYE_HEIGHT`]
//!   times the eye's height above the resident ground: a camera 10 m up
//!   with a 1024² window gets level 0 of a 0.3 m field; from 1 km up the
//!   window's level has 32 m samples. Where no level is both finer and wide
//!   enough, there is no window (the resident level already suffices).
//! * **Where.** Whole tiles (`side` rounds up to whole tiles), centred on
//!   the tile corner nearest the camera's ground point, clamped into the
//!   level. The image is toroidal: level sample `(c, r)` lives at texel
//!   `(c mod side, r mod side)`, so a move re-uploads only the tiles that
//!   enter.
//! * **Asynchronous.** [`crate::io::pyramid::stream::TileStream`] reads
//!   tiles on its own thread into an LRU host cache of
//!   [`CACHE_WINDOWS`]× the window's tiles; `prepare` takes what arrived,
//!   writes it into the frame's upload region (`terrain.detail` copies it
//!   into the image) and into a host mirror of the image (the CPU twin).
//!   A frame that does not wait uploads at most [`UPLOAD_BUDGET_TILES`],
//!   nearest to the eye first, so a jump of the window spreads over frames.
//! * **Coarser until finer arrives.** The *active* rectangle is the part of
//!   the window the image holds: the whole window once its tiles are all
//!   uploaded, until then what the previous active rectangle and the new
//!   window share (those slots are never overwritten by the new tiles),
//!   else nothing; outside it the resident level is drawn.
//! * **No seam.** Within the active rectangle, less the B-spline's support
//!   (one sample in, two out), heights blend from the resident level to the
//!   window over [`BLEND_BAND`] window samples with a smoothstep per side
//!   (a product, so the blend and its gradient are smooth); a side on the
//!   level's edge blends nothing (both clamp there alike). Gradients (the
//!   normals) are the blend's exact derivative. `glsl/include/detail_window.glsl`
//!   and [`DetailWindow::height`] are the two sides of it.
//! * **Deterministic frames.** With `wait` set, `prepare` waits until the
//!   window's tiles arrived (the CLI's `render` and the tests); without it
//!   frames never wait on the disk.

mod ground;
mod pass;
#[cfg(test)]
pub(crate) mod tests;

use std::path::PathBuf;

use glam::{DVec2, DVec3};

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::io::pyramid::stream::TileStream;
use crate::io::pyramid::{HeightPyramid, PyramidTile, TileKey};
use crate::surface::bspline::sample_bspline;
#[cfg(test)]
use crate::surface::bspline::{cubic_bspline_derivative_weights, cubic_bspline_weights, sample_bspline_gradient};

pub use ground::StreamedGround;
pub use pass::{declare_detail_upload, DetailDevice, DetailPush, DetailUploads};

/// Default window side in samples (`--detail-window`).
pub const DEFAULT_DETAIL_WINDOW: u32 = 1024;
/// Largest window side.
pub const MAX_DETAIL_WINDOW: u32 = 8192;
/// The window's level spans at least this many eye heights (module docs).
pub const GROUND_PER_EYE_HEIGHT: f64 = 32.0;
/// Window samples over which heights blend from the resident level.
pub const BLEND_BAND: f64 = 32.0;
/// The host cache holds this many windows' tiles.
pub const CACHE_WINDOWS: usize = 2;
/// Most tiles a frame that does not wait uploads (1 MiB of R32F at 256²
/// tiles): a window that jumps (a new level, a teleport) fills over
/// several frames, nearest tiles first, instead of stalling one.
pub const UPLOAD_BUDGET_TILES: usize = 4;

/// Where a scene's detail streams from.
#[derive(Clone, Debug, PartialEq)]
pub struct DetailSource {
    /// The height pyramid (`.hpyr`).
    pub path: PathBuf,
    /// The level the scene holds resident (its sketch atlas).
    pub resident_level: u32,
    /// Window side in samples (rounded up to whole tiles); 0: no window.
    pub window: u32,
    /// Whether `prepare` waits for the window's tiles (deterministic frames).
    pub wait: bool,
}

/// A rectangle of whole tiles `[x0, x1) × [y0, y1)` of one level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileRect {
    pub level: u32,
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl TileRect {
    fn keys(self) -> impl Iterator<Item = TileKey> {
        (self.y0..self.y1).flat_map(move |y| {
            (self.x0..self.x1).map(move |x| TileKey {
                level: self.level,
                x,
                y,
            })
        })
    }

    fn intersect(self, o: TileRect) -> Option<TileRect> {
        let r = TileRect {
            level: self.level,
            x0: self.x0.max(o.x0),
            y0: self.y0.max(o.y0),
            x1: self.x1.min(o.x1),
            y1: self.y1.min(o.y1),
        };
        (self.level == o.level && r.x0 < r.x1 && r.y0 < r.y1).then_some(r)
    }
}

/// One tile for `terrain.detail`: its texel corner in the image and samples.
pub struct TileUpload {
    pub corner: (u32, u32),
    pub tile: PyramidTile,
}

/// The detail window's host side: the stream, the image's slots and their
/// host mirror, the active rectangle.
pub struct DetailWindow {
    stream: TileStream,
    /// Samples a side of every level, and their spacing.
    levels: Vec<((u32, u32), DVec2)>,
    tile: u32,
    /// Tiles a side of the window.
    tiles: u32,
    resident_level: u32,
    wait: bool,
    /// Which tile each slot of the image holds.
    slots: Vec<Option<TileKey>>,
    /// The image's texels as uploaded (`side`², row-major).
    mirror: Vec<f32>,
    wanted: Option<TileRect>,
    active: Option<TileRect>,
}

impl DetailWindow {
    /// The window of `source` (None when it asks for none, or the resident
    /// level is the finest).
    pub fn open(source: &DetailSource) -> Result<Option<DetailWindow>> {
        if source.window == 0 || source.resident_level == 0 {
            return Ok(None);
        }
        if source.window > MAX_DETAIL_WINDOW {
            return Err(Error::invalid(
                "detail window",
                format!("{} samples (at most {MAX_DETAIL_WINDOW})", source.window),
            ));
        }
        let pyramid = HeightPyramid::open(&source.path)?;
        let tile = pyramid.tile_side();
        let tiles = source.window.div_ceil(tile);
        let levels = (0..pyramid.levels())
            .map(|l| (pyramid.level_size(l), pyramid.level_spacing(l)))
            .collect();
        let stream = TileStream::open(&source.path, CACHE_WINDOWS * (tiles * tiles) as usize)?;
        Ok(Some(DetailWindow {
            stream,
            levels,
            tile,
            tiles,
            resident_level: source.resident_level.min(pyramid.levels() - 1),
            wait: source.wait,
            slots: vec![None; (tiles * tiles) as usize],
            mirror: vec![0.0; (tiles * tile).pow(2) as usize],
            wanted: None,
            active: None,
        }))
    }

    /// Samples a side of the image.
    pub fn side(&self) -> u32 {
        self.tiles * self.tile
    }

    /// Samples a side of a tile.
    pub fn tile_side(&self) -> u32 {
        self.tile
    }

    /// Most tiles one frame uploads (the whole window).
    pub fn max_uploads(&self) -> u32 {
        self.tiles * self.tiles
    }

    /// The level and tiles the window wants for an eye at `eye`, `ground`
    /// metres being the resident ground's height below it.
    pub fn plan(&self, eye: DVec3, ground: f64) -> Option<TileRect> {
        let need = GROUND_PER_EYE_HEIGHT * (eye.z - ground).max(0.0);
        let side = f64::from(self.side());
        let level = (0..self.resident_level).find(|&l| side * self.levels[l as usize].1.min_element() >= need)?;
        let ((columns, rows), spacing) = self.levels[level as usize];
        let t = f64::from(self.tile);
        let k = self.tiles;
        let span = |samples: u32, coord: f64, step: f64| {
            let n = samples.div_ceil(self.tile);
            let corner = (coord / step / t).round().clamp(0.0, f64::from(n)) as u32;
            let first = corner.saturating_sub(k / 2).min(n.saturating_sub(k));
            (first, (first + k).min(n))
        };
        let (x0, x1) = span(columns, eye.x, spacing.x);
        let (y0, y1) = span(rows, eye.y, spacing.y);
        Some(TileRect { level, x0, y0, x1, y1 })
    }

    /// This frame's window: takes the tiles that arrived, asks for the
    /// window's missing ones (waits for them when `wait` is set) and
    /// returns the tiles to upload, the image's slots and mirror updated.
    /// `resident` is the scene's resident field (for the ground below
    /// the eye).
    pub fn update(&mut self, eye: DVec3, resident: &HeightField) -> Result<Vec<TileUpload>> {
        self.stream.receive()?;
        let ground = sample_bspline(resident, eye.x, eye.y);
        self.wanted = self.plan(eye, ground);
        let Some(wanted) = self.wanted else {
            self.active = None;
            return Ok(Vec::new());
        };
        // Nearest to the eye first: those are requested, and within the
        // budget uploaded, first.
        let mut keys: Vec<TileKey> = wanted.keys().collect();
        let ((_, _), spacing) = self.levels[wanted.level as usize];
        let eye_tile = eye.truncate() / (spacing * f64::from(self.tile)) - 0.5;
        keys.sort_by_key(|k| {
            let d = DVec2::new(f64::from(k.x), f64::from(k.y)) - eye_tile;
            (d.length_squared() * 1024.0) as u64
        });
        for &key in &keys {
            self.stream.request(key)?;
        }
        if self.wait {
            self.stream.wait_for(&keys)?;
        }
        // A waiting frame takes the whole window (deterministic); others
        // at most the budget.
        let budget = if self.wait { keys.len() } else { UPLOAD_BUDGET_TILES };
        let mut uploads = Vec::new();
        for &key in &keys {
            let slot = self.slot(key);
            let held = self.slots[slot] == Some(key);
            // Every wanted tile is marked used, so the LRU drops others first.
            let Some(tile) = self.stream.cache().get(key) else {
                continue;
            };
            if held || uploads.len() >= budget {
                continue;
            }
            let tile = tile.clone();
            self.write_mirror(&tile);
            self.slots[slot] = Some(key);
            let corner = ((key.x % self.tiles) * self.tile, (key.y % self.tiles) * self.tile);
            uploads.push(TileUpload { corner, tile });
        }
        if !uploads.is_empty() {
            let cache = self.stream.cache();
            log::debug!(
                "detail window: {} tiles of level {} uploaded; host cache {} of {} tiles ({} bytes)",
                uploads.len(),
                wanted.level,
                cache.len(),
                cache.capacity(),
                cache.bytes()
            );
        }
        let holds = |r: TileRect| r.keys().all(|k| self.slots[self.slot(k)] == Some(k));
        self.active = if holds(wanted) {
            Some(wanted)
        } else {
            self.active.and_then(|a| a.intersect(wanted)).filter(|&r| holds(r))
        };
        Ok(uploads)
    }

    fn slot(&self, key: TileKey) -> usize {
        ((key.y % self.tiles) * self.tiles + key.x % self.tiles) as usize
    }

    fn write_mirror(&mut self, tile: &PyramidTile) {
        let side = self.side() as usize;
        let (cx, cy) = (
            ((tile.key.x % self.tiles) * self.tile) as usize,
            ((tile.key.y % self.tiles) * self.tile) as usize,
        );
        for (r, row) in tile.heights.chunks_exact(tile.width as usize).enumerate() {
            let at = (cy + r) * side + cx;
            self.mirror[at..at + row.len()].copy_from_slice(row);
        }
    }

    /// The window the camera wants (after [`DetailWindow::update`]).
    #[cfg(test)]
    pub fn wanted(&self) -> Option<TileRect> {
        self.wanted
    }

    /// The part of the window drawn this frame.
    #[cfg(test)]
    pub fn active(&self) -> Option<TileRect> {
        self.active
    }

    /// Tiles in the host cache, and its capacity.
    #[cfg(test)]
    pub fn cache_tiles(&mut self) -> (usize, usize) {
        let cache = self.stream.cache();
        (cache.len(), cache.capacity())
    }

    /// The shader's view of the active window (its handle left 0).
    pub fn push(&self) -> DetailPush {
        let Some(a) = self.active else {
            return DetailPush::default();
        };
        let ((columns, rows), spacing) = self.levels[a.level as usize];
        let b = self.bounds(a);
        DetailPush {
            grid: [0, self.side(), columns, rows],
            valid: [b[0] as f32, b[1] as f32, b[2] as f32, b[3] as f32],
            spacing: [spacing.x as f32, spacing.y as f32, BLEND_BAND as f32, 1.0],
        }
    }

    /// Where the B-spline of the active rectangle `a` has all its taps in
    /// it, in level samples (lo x, lo y, hi x, hi y; unbounded on the
    /// level's edges).
    fn bounds(&self, a: TileRect) -> [f64; 4] {
        let ((columns, rows), _) = self.levels[a.level as usize];
        let t = self.tile;
        let lo = |first: u32| if first == 0 { -1e30 } else { f64::from(first * t) + 1.0 };
        let hi = |end: u32, n: u32| {
            if end * t >= n {
                1e30
            } else {
                f64::from(end * t - 1) - 2.0
            }
        };
        [lo(a.x0), lo(a.y0), hi(a.x1, columns), hi(a.y1, rows)]
    }

    /// The height and gradient drawn at world `(x, y)`: the resident
    /// field's B-spline blended into the window's (the CPU twin of
    /// `detail_window.glsl`, from the host mirror of the image; the ground
    /// queries do not use it yet).
    #[cfg(test)]
    pub fn height(&self, resident: &HeightField, x: f64, y: f64) -> (f64, DVec2) {
        let coarse = sample_bspline(resident, x, y);
        let coarse_grad = sample_bspline_gradient(resident, x, y);
        let Some(a) = self.active else {
            return (coarse, coarse_grad);
        };
        let ((columns, rows), spacing) = self.levels[a.level as usize];
        let b = self.bounds(a);
        let g = DVec2::new(x, y) / spacing;
        let (wx, dwx) = side_pair(g.x - b[0], b[2] - g.x);
        let (wy, dwy) = side_pair(g.y - b[1], b[3] - g.y);
        let w = wx * wy;
        if w <= 0.0 {
            return (coarse, coarse_grad);
        }
        let (fine, fine_grad) = self.window_bspline((columns, rows), spacing, g);
        let dw = DVec2::new(dwx * wy / spacing.x, wx * dwy / spacing.y);
        let h = coarse + (fine - coarse) * w;
        (h, coarse_grad + (fine_grad - coarse_grad) * w + (fine - coarse) * dw)
    }

    /// The window's B-spline at level sample coordinates `g` (clamped to
    /// the level like `bspline_height`).
    #[cfg(test)]
    fn window_bspline(&self, (columns, rows): (u32, u32), spacing: DVec2, g: DVec2) -> (f64, DVec2) {
        let side = self.side() as usize;
        let axis = |v: f64, n: u32| {
            let v = v.clamp(0.0, f64::from(n - 1));
            let base = v.floor();
            let taps = [-1i64, 0, 1, 2].map(|o| (base as i64 + o).clamp(0, i64::from(n) - 1) as usize % side);
            (
                taps,
                cubic_bspline_weights(v - base),
                cubic_bspline_derivative_weights(v - base),
            )
        };
        let (cx, wx, dx) = axis(g.x, columns);
        let (cy, wy, dy) = axis(g.y, rows);
        let (mut h, mut grad) = (0.0, DVec2::ZERO);
        for j in 0..4 {
            for i in 0..4 {
                let v = f64::from(self.mirror[cy[j] * side + cx[i]]);
                h += wx[i] * wy[j] * v;
                grad += DVec2::new(dx[i] * wy[j], wx[i] * dy[j]) * v;
            }
        }
        (h, grad / spacing)
    }
}

/// The smoothstep weight of one axis's two sides at distances `lo`, `hi`
/// (window samples) from their bounds, and its derivative along the axis.
#[cfg(test)]
fn side_pair(lo: f64, hi: f64) -> (f64, f64) {
    let (a, da) = smooth(lo);
    let (b, db) = smooth(hi);
    (a * b, da * b - a * db)
}

/// `smoothstep(0, BLEND_BAND, d)` and its derivative in `d`.
#[cfg(test)]
fn smooth(d: f64) -> (f64, f64) {
    let t = (d / BLEND_BAND).clamp(0.0, 1.0);
    let dt = if d > 0.0 && d < BLEND_BAND {
        1.0 / BLEND_BAND
    } else {
        0.0
    };
    (t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t) * dt)
}
