//! Reading pyramid tiles in the background into a bounded host cache
//! (issue 31 item 1; §7.4.4 keeps "a large sketch atlas in main memory and
//! only the visible part in video memory"): a reader thread owns its own
//! [`HeightPyramid`] and answers tile requests over channels, so the
//! frame's `prepare` never waits on the disk (unless it asks to:
//! [`TileStream::wait_for`]) and no lock is shared with anything.
//!
//! [`TileStream`] is the consumer's side: [`TileStream::request`] sends a
//! key once (not again while it is pending or cached),
//! [`TileStream::receive`] moves what arrived into the [`TileCache`], a
//! least-recently-used cache of at most `capacity` tiles. A tile the reader
//! could not read (a checksum, a short read) arrives as the one-line error
//! naming the file and the tile, which `receive` returns.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{self, Receiver, Sender, TryRecvError};
use std::thread::JoinHandle;

use super::{HeightPyramid, PyramidTile, TileKey};
use crate::error::{Error, Result};

/// A least-recently-used cache of decoded tiles, at most `capacity` of them.
#[derive(Debug)]
pub struct TileCache {
    capacity: usize,
    tiles: HashMap<TileKey, (PyramidTile, u64)>,
    clock: u64,
}

impl TileCache {
    /// An empty cache of at most `capacity` (≥ 1) tiles.
    pub fn new(capacity: usize) -> TileCache {
        TileCache {
            capacity: capacity.max(1),
            tiles: HashMap::new(),
            clock: 0,
        }
    }

    /// The tile of `key`, marked as used now.
    pub fn get(&mut self, key: TileKey) -> Option<&PyramidTile> {
        self.clock += 1;
        let clock = self.clock;
        self.tiles.get_mut(&key).map(|(tile, used)| {
            *used = clock;
            &*tile
        })
    }

    /// Whether `key` is cached (without marking it used).
    pub fn contains(&self, key: TileKey) -> bool {
        self.tiles.contains_key(&key)
    }

    /// Adds `tile`, dropping the least recently used tiles beyond the capacity.
    pub fn insert(&mut self, tile: PyramidTile) {
        self.clock += 1;
        self.tiles.insert(tile.key, (tile, self.clock));
        while self.tiles.len() > self.capacity {
            let oldest = (self.tiles.iter().min_by_key(|(_, (_, used))| *used)).map(|(k, _)| *k);
            if let Some(k) = oldest {
                self.tiles.remove(&k);
            }
        }
    }

    /// Tiles held.
    pub fn len(&self) -> usize {
        self.tiles.len()
    }

    /// Whether no tile is held.
    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.tiles.is_empty()
    }

    /// Most tiles held.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Bytes of the heights held.
    pub fn bytes(&self) -> u64 {
        self.tiles.values().map(|(t, _)| 4 * t.heights.len() as u64).sum()
    }
}

/// One answer of the reader thread.
type Arrival = (TileKey, Result<PyramidTile>);

/// Tiles of one pyramid read by a background thread into a [`TileCache`].
#[derive(Debug)]
pub struct TileStream {
    path: PathBuf,
    requests: Option<Sender<TileKey>>,
    arrivals: Receiver<Arrival>,
    reader: Option<JoinHandle<()>>,
    pending: HashSet<TileKey>,
    cache: TileCache,
}

impl TileStream {
    /// Opens `path` (its header and index, checked here) and starts the
    /// reader thread; the cache holds at most `capacity` tiles.
    pub fn open(path: &Path, capacity: usize) -> Result<TileStream> {
        let pyramid = HeightPyramid::open(path)?;
        let (requests, inbox) = mpsc::channel::<TileKey>();
        let (outbox, arrivals) = mpsc::channel::<Arrival>();
        let reader = std::thread::Builder::new()
            .name("alpenglow pyramid reader".into())
            .spawn(move || {
                // Ends when the stream drops its sender (or its receiver).
                for key in inbox {
                    if outbox.send((key, pyramid.read_tile(key))).is_err() {
                        break;
                    }
                }
            })
            .map_err(|e| Error::input(path, format!("cannot start the tile reader: {e}")))?;
        Ok(TileStream {
            path: path.to_path_buf(),
            requests: Some(requests),
            arrivals,
            reader: Some(reader),
            pending: HashSet::new(),
            cache: TileCache::new(capacity),
        })
    }

    /// Asks for `key` unless it is cached or already asked for; at most
    /// the cache's capacity of requests are pending (false: not asked now,
    /// ask again later).
    pub fn request(&mut self, key: TileKey) -> Result<bool> {
        if self.cache.contains(key) || self.pending.contains(&key) {
            return Ok(true);
        }
        if self.pending.len() >= self.cache.capacity() {
            return Ok(false);
        }
        let sent = self.requests.as_ref().is_some_and(|s| s.send(key).is_ok());
        if !sent {
            return Err(self.reader_gone());
        }
        self.pending.insert(key);
        Ok(true)
    }

    /// Moves every tile that arrived into the cache (never waits); the
    /// number moved, or the first tile's read error.
    pub fn receive(&mut self) -> Result<usize> {
        let mut moved = 0;
        loop {
            match self.arrivals.try_recv() {
                Ok(arrival) => {
                    self.accept(arrival)?;
                    moved += 1;
                }
                Err(TryRecvError::Empty) => return Ok(moved),
                Err(TryRecvError::Disconnected) => return Err(self.reader_gone()),
            }
        }
    }

    /// Waits until every key of `keys` is cached (requesting the missing).
    pub fn wait_for(&mut self, keys: &[TileKey]) -> Result<()> {
        loop {
            self.receive()?;
            let mut missing = false;
            for &key in keys {
                if !self.cache.contains(key) {
                    missing = true;
                    self.request(key)?;
                }
            }
            if !missing {
                return Ok(());
            }
            if self.pending.is_empty() {
                continue;
            }
            let arrival = self.arrivals.recv().map_err(|_| self.reader_gone())?;
            self.accept(arrival)?;
        }
    }

    fn accept(&mut self, (key, tile): Arrival) -> Result<()> {
        self.pending.remove(&key);
        self.cache.insert(tile?);
        Ok(())
    }

    fn reader_gone(&self) -> Error {
        Error::input(&self.path, "the tile reader thread stopped")
    }

    /// The cache (to take tiles from, and for its size).
    pub fn cache(&mut self) -> &mut TileCache {
        &mut self.cache
    }

    /// Requests sent and not yet received.
    #[cfg(test)]
    pub fn pending(&self) -> usize {
        self.pending.len()
    }
}

impl Drop for TileStream {
    fn drop(&mut self) {
        // Without its receiver the reader's next answer fails and it ends
        // (without reading the rest of its queue).
        self.requests = None;
        drop(std::mem::replace(&mut self.arrivals, mpsc::channel().1));
        if let Some(reader) = self.reader.take() {
            let _ = reader.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use glam::DVec2;

    use super::*;
    use crate::io::heightmap::HeightField;
    use crate::io::pyramid::{write_pyramid, FieldRows, PyramidOptions};

    fn pyramid(name: &str, side: u32, tile_side: u32) -> (PathBuf, HeightField) {
        let dir = std::env::temp_dir().join(format!("alpenglow-stream-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        let field = HeightField::from_fn(side, side, DVec2::splat(2.0), |c, r| {
            ((c * 7 + r * 13) % 101) as f32 * 0.5 + c as f32 * 0.25
        });
        let options = PyramidOptions {
            tile_side,
            ..PyramidOptions::default()
        };
        write_pyramid(&path, &mut FieldRows::new(&field, Path::new("test")), &options).unwrap();
        (path, field)
    }

    #[test]
    fn the_cache_keeps_the_most_recent_tiles_within_its_capacity() {
        let (path, field) = pyramid("lru.hpyr", 129, 16);
        let mut stream = TileStream::open(&path, 5).unwrap();
        assert!(stream.cache().is_empty());
        let keys: Vec<TileKey> = (0..8).map(|x| TileKey { level: 0, x, y: 1 }).collect();
        for chunk in keys.chunks(2) {
            stream.wait_for(chunk).unwrap();
            assert!(stream.cache().len() <= 5);
        }
        // The last five asked for stay; the first three were dropped.
        for (k, key) in keys.iter().enumerate() {
            assert_eq!(stream.cache().contains(*key), k >= 3, "{key}");
        }
        let tile = stream.cache().get(keys[7]).unwrap().clone();
        assert_eq!((tile.width, tile.height), (16, 16));
        assert_eq!(tile.heights[3 * 16 + 2], field.heights[(16 + 3) * 129 + 7 * 16 + 2]);
        assert_eq!(stream.cache().bytes(), 5 * 16 * 16 * 4);
        assert_eq!(stream.pending(), 0);
    }

    #[test]
    fn a_corrupt_tile_read_in_the_background_is_a_one_line_error() {
        let (path, _) = pyramid("corrupt-stream.hpyr", 64, 16);
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[100] ^= 0x40; // inside the first tile (level 0, tile (0, 0))
        let bad = path.with_file_name("corrupt-tile.hpyr");
        std::fs::write(&bad, &bytes).unwrap();
        let mut stream = TileStream::open(&bad, 4).unwrap();
        let key = TileKey { level: 0, x: 0, y: 0 };
        let err = stream.wait_for(&[key]).unwrap_err().to_string();
        assert!(
            err.contains("corrupt-tile.hpyr") && err.contains("tile (0, 0) of level 0"),
            "{err}"
        );
        assert!(err.contains("checksum"), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        // The stream goes on: other tiles still arrive.
        stream.wait_for(&[TileKey { level: 0, x: 1, y: 0 }]).unwrap();
    }
}
