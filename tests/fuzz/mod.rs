//! The fuzz harness: seeds from `tests/data/fuzz/<loader>/`, mutated (see
//! `mutate`), written to a temporary file and given to the loader.
//!
//! Every case must end in a valid result (the loader's own validation is
//! run again on it) or an error whose message is one non-empty line naming
//! the file; a panic, an allocation above `alloc::MAX_SINGLE` or a heap rise
//! above `alloc::MAX_PEAK` fails the test.
//!
//! Environment: `ALPENGLOW_FUZZ_CASES` (cases per loader, default 400),
//! `ALPENGLOW_FUZZ_SECONDS` (keep going until this many seconds have passed
//! per loader, for longer local runs), `ALPENGLOW_FUZZ_SEED` (base seed,
//! default fixed, so CI is reproducible), `ALPENGLOW_FUZZ_REPLAY` (one
//! arbtest seed, hex, as printed by a failure: runs that case alone).

pub mod alloc;
pub mod mutate;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use arbitrary::Unstructured;
use mutate::Kind;

/// What a loader made of a case: `Ok(Err(_))` is a loaded result that
/// fails its own validation (a bug), `Err(_)` an ordinary error.
pub type Outcome = std::result::Result<std::result::Result<(), String>, alpenglow::Error>;

/// One loader under test.
pub struct Target {
    /// Corpus folder under `tests/data/fuzz/`.
    pub corpus: &'static str,
    /// Extension of the case files (the loaders dispatch on it).
    pub extension: &'static str,
    pub kind: Kind,
    /// Repairs a checksum after mutation (most of the time), or nothing.
    pub fixup: fn(&mut [u8]),
    pub load: fn(&Path) -> Outcome,
}

/// No repair.
pub fn no_fixup(_: &mut [u8]) {}

/// Cases of different loaders run one at a time: the heap counters are
/// process-wide.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Cases that loaded (and passed validation), for the summary line.
static LOADED: AtomicU64 = AtomicU64::new(0);

fn env_u64(name: &str) -> Option<u64> {
    let v = std::env::var(name).ok()?;
    let v = v.trim();
    match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => v.parse().ok(),
    }
}

fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

fn seeds(corpus: &str) -> Vec<Vec<u8>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fuzz")
        .join(corpus);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("corpus {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    paths.sort();
    assert!(!paths.is_empty(), "corpus {} is empty", dir.display());
    paths.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

/// Runs the loader on `bytes` and checks the outcome; panics (with a saved
/// copy of the case) on a violation.
fn check(target: &Target, bytes: &[u8], case: u64, must_load: bool) {
    let path = std::env::temp_dir().join(format!(
        "alpenglow-fuzz-{}-{}.{}",
        std::process::id(),
        target.corpus,
        target.extension
    ));
    std::fs::write(&path, bytes).unwrap();
    let base = alloc::start();
    let outcome = catch_unwind(AssertUnwindSafe(|| (target.load)(&path)));
    let rise = alloc::rise(base);
    let _ = std::fs::remove_file(&path);
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let problem = match &outcome {
        Err(_) => Some("the loader panicked".to_string()),
        Ok(Ok(Err(why))) => Some(format!("loaded, but the result is invalid: {why}")),
        Ok(Err(e)) if must_load => Some(format!("a seed file does not load: {e}")),
        Ok(Err(e)) => {
            let m = e.to_string();
            if m.trim().is_empty() || m.contains('\n') || m.contains('\r') {
                Some(format!("the error is not one line: {m:?}"))
            } else if !m.contains(&name) {
                Some(format!("the error does not name the file: {m:?}"))
            } else {
                None
            }
        }
        Ok(Ok(Ok(()))) => {
            LOADED.fetch_add(1, Ordering::Relaxed);
            None
        }
    };
    let problem = problem.or_else(|| {
        (rise > alloc::MAX_PEAK).then(|| format!("the heap rose by {rise} bytes (limit {})", alloc::MAX_PEAK))
    });
    if let Some(problem) = problem {
        let saved = std::env::temp_dir().join(format!(
            "fuzz-failure-{}-{case:016x}.{}",
            target.corpus, target.extension
        ));
        std::fs::write(&saved, bytes).unwrap();
        panic!(
            "fuzz {} case 0x{case:016x}: {problem}; input saved as {}; replay with \
             ALPENGLOW_FUZZ_REPLAY=0x{case:016x} cargo test --test fuzz_loaders {}",
            target.corpus,
            saved.display(),
            target.corpus
        );
    }
}

/// One arbtest case: mutate a seed and check the loader.
fn run_case(target: &Target, seeds: &[Vec<u8>], case: u64) {
    alloc::CASE.store(case, Ordering::Relaxed);
    arbtest::arbtest(|u: &mut Unstructured| {
        let mut bytes = mutate::mutate(seeds, target.kind, u)?;
        if u.ratio(3, 4)? {
            (target.fixup)(&mut bytes);
        }
        check(target, &bytes, case, false);
        Ok(())
    })
    .seed(case)
    .run();
}

/// Fuzzes `target`: its seeds must load, then the mutated cases; returns
/// the number of cases run.
pub fn fuzz(target: &Target) -> u64 {
    let _guard = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let seeds = seeds(target.corpus);
    if let Some(case) = env_u64("ALPENGLOW_FUZZ_REPLAY") {
        run_case(target, &seeds, case);
        return 1;
    }
    for seed in &seeds {
        check(target, seed, 0, true);
    }
    let cases = env_u64("ALPENGLOW_FUZZ_CASES").unwrap_or(400);
    let budget = env_u64("ALPENGLOW_FUZZ_SECONDS").map(Duration::from_secs);
    let base = env_u64("ALPENGLOW_FUZZ_SEED").unwrap_or(0xa1be_9100)
        ^ splitmix64(target.corpus.len() as u64)
        ^ target.corpus.bytes().fold(0u64, |h, b| splitmix64(h ^ u64::from(b)));
    let start = Instant::now();
    LOADED.store(0, Ordering::Relaxed);
    let mut n = 0u64;
    while n < cases || budget.is_some_and(|b| start.elapsed() < b) {
        let r = splitmix64(base.wrapping_add(n));
        // arbtest seed: high half random, low half the input size (64..4159 bytes).
        let case = (r & !0xffff_ffff) | (64 + (r & 0xfff));
        run_case(target, &seeds, case);
        n += 1;
    }
    eprintln!(
        "fuzz {}: {n} cases in {:.1} s, {} loaded, the rest one-line errors",
        target.corpus,
        start.elapsed().as_secs_f64(),
        LOADED.load(Ordering::Relaxed)
    );
    n
}

/// Checks every file of `tests/data/fuzz-regressions/<folder>/` (inputs
/// that once crashed, hung or blew up memory): each must give a valid result
/// or a one-line error, within the memory limits. Returns the file count.
pub fn regressions(target: &Target, folder: &str) -> usize {
    let _guard = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fuzz-regressions")
        .join(folder);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    paths.sort();
    for (k, p) in paths.iter().enumerate() {
        check(target, &std::fs::read(p).unwrap(), k as u64, false);
    }
    paths.len()
}
