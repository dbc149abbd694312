//! A counting global allocator: the fuzz binary fails a case whose loader
//! asks for one block above [`MAX_SINGLE`] (refused: the process aborts
//! with a message naming the case) or whose peak rises more than
//! [`MAX_PEAK`] above the start of the case.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

/// Largest single allocation a loader may make (512 MiB).
pub const MAX_SINGLE: usize = 512 << 20;
/// Largest rise of the live heap during one case (1 GiB).
pub const MAX_PEAK: usize = 1 << 30;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// The arbtest seed of the running case, for the abort message.
pub static CASE: AtomicU64 = AtomicU64::new(0);

/// Counts live bytes and the peak; refuses single blocks above [`MAX_SINGLE`].
pub struct Counting;

fn refuse(size: usize) {
    // No allocation here: a fixed message and the numbers in hex.
    let mut line = *b"fuzz_loaders: refused an allocation of 0x0000000000000000 bytes in case 0x0000000000000000\n";
    let hex = |out: &mut [u8], v: u64| {
        for (k, slot) in out.iter_mut().enumerate() {
            let nibble = (v >> (60 - 4 * k)) & 0xf;
            *slot = b"0123456789abcdef"[nibble as usize];
        }
    };
    hex(&mut line[41..57], size as u64);
    hex(&mut line[74..90], CASE.load(Ordering::Relaxed));
    let _ = std::io::stderr().write_all(&line);
}

fn added(size: usize) {
    let live = LIVE.fetch_add(size, Ordering::Relaxed) + size;
    PEAK.fetch_max(live, Ordering::Relaxed);
}

// SAFETY: every call is forwarded to the system allocator with the same
// layout; the counters are atomics and never allocate.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > MAX_SINGLE {
            refuse(layout.size());
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded unchanged (see the impl's SAFETY note).
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            added(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `alloc`/`realloc` above with this layout.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > MAX_SINGLE {
            refuse(new_size);
            return std::ptr::null_mut();
        }
        // SAFETY: forwarded unchanged (see the impl's SAFETY note).
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
            added(new_size);
        }
        p
    }
}

/// Starts a case: the peak is reset to the live heap, which is returned.
pub fn start() -> usize {
    let live = LIVE.load(Ordering::Relaxed);
    PEAK.store(live, Ordering::Relaxed);
    live
}

/// The rise of the peak since `start` returned `base`.
pub fn rise(base: usize) -> usize {
    PEAK.load(Ordering::Relaxed).saturating_sub(base)
}
