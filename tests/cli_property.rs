//! Property test of the command line's option space (issue 25, item 6):
//! random and extreme values (NaN, ±inf, 0, -0, negatives, 1e308, 1e-300,
//! u64::MAX + 1, each documented limit and just beyond it, comma lists
//! with a bad element or a wrong count) for every numeric option of
//! `render`, `bench`, `fly`, `spt build`, `synth fill`, `synth grow`, `synth transition`
//! and `layers from-image`, each mixed into a small valid command line
//! (32×24 images, 33² terrains, a few frames, tiny input files) and run
//! with the debug binary under `--validation`. A case passes when the run
//!
//! * does not panic or die of a signal, ends within 60 s and stays under
//!   4 GiB resident (`ALPENGLOW_HOST_MEMORY_MB=1024` for the memory model,
//!   so large counts are refused before they allocate);
//! * exits 0 with every output valid (PNG and EXR decode, JSON parses,
//!   SPT, height map and layer tree load) and accepted no NaN; or
//! * exits non-zero with stderr of warning lines and one `error:` line
//!   naming an option the command line contains (the first one it names)
//!   or one of its files, and no output file left behind.
//!
//! Environment (as `tests/fuzz_loaders.rs`): `ALPENGLOW_CLI_PROPTEST_CASES`
//! (default 100), `ALPENGLOW_CLI_PROPTEST_SECONDS` (keep going until this
//! many seconds have passed), `ALPENGLOW_CLI_PROPTEST_SEED` (base seed,
//! decimal or 0x hex; fixed by default), `ALPENGLOW_CLI_PROPTEST_REPLAY`
//! (one case id, as printed by a failure). Cases run on 2 threads. See
//! docs/FUZZING.md.

mod cli_property {
    pub mod case;
    pub mod options;
    pub mod run;
    pub mod values;
}

use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use cli_property::case::{generate, shell_line, Case, Fixtures};
use cli_property::options::Command;
use cli_property::run::{judge, run, HOST_MEMORY_MB};
use cli_property::values::splitmix64;

fn env_u64(name: &str) -> Option<u64> {
    let v = std::env::var(name).ok()?;
    let v = v.trim();
    match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16).ok(),
        None => v.parse().ok(),
    }
}

/// The value options `alpenglow WORDS --help` lists (`--flag <VALUE>`).
fn help_value_options(words: &[&str]) -> Vec<String> {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_alpenglow"))
        .args(words)
        .arg("--help")
        .output()
        .expect("runs");
    assert!(out.status.success(), "{words:?} --help failed");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::trim_start)
        .filter(|l| l.starts_with("--"))
        .filter_map(|l| {
            let (flag, rest) = l.split_once(' ')?;
            rest.starts_with('<').then(|| flag.to_string())
        })
        .collect()
}

/// Every option that takes a value is listed by the property test, as
/// numeric (varied) or as other (files, modes), and every listed option
/// exists: a new numeric option cannot be forgotten.
#[test]
fn every_option_is_listed() {
    for command in Command::ALL {
        let help = help_value_options(command.words());
        let numeric: Vec<&str> = command.numeric().iter().map(|o| o.flag).collect();
        let other = command.other();
        for flag in &help {
            assert!(
                numeric.contains(&flag.as_str()) || other.contains(&flag.as_str()),
                "{:?} {flag}: not listed in tests/cli_property/options.rs \
                 (add it to the numeric options with its range, or to the others)",
                command.words()
            );
        }
        for flag in numeric.iter().chain(&other) {
            assert!(
                help.iter().any(|h| h == flag),
                "{:?}: {flag} is listed but not in --help",
                command.words()
            );
        }
    }
}

/// The error lines' option groups are found as the culprit check reads them.
#[test]
fn named_flags_reads_groups() {
    use cli_property::run::named_flags;
    assert_eq!(
        named_flags("error: invalid --near/--far: near 0 (see alpenglow --help)"),
        vec![vec!["--near".to_string(), "--far".to_string()]]
    );
    assert_eq!(
        named_flags("error: --terrain 'x': set --height-scale"),
        vec![vec!["--terrain".to_string()], vec!["--height-scale".to_string()]]
    );
    assert!(named_flags("error: a-b --- c").is_empty());
}

/// The outcome of one case.
enum Verdict {
    Ok,
    Error,
    Failed(String),
}

fn run_case(id: u64, fixtures: &Fixtures, root: &Path) -> Verdict {
    let case: Case = generate(id, fixtures, root);
    let scratch = root.join(format!("run-{id:016x}"));
    let result = run(&case, &scratch);
    let verdict = match judge(&case, &result) {
        None if result.code == Some(0) => Verdict::Ok,
        None => Verdict::Error,
        Some((problem, why)) => {
            let line = format!(
                "{} case 0x{id:016x} ({problem:?}, {:.1} s, {} MiB peak): {why}\n  command: \
                 ALPENGLOW_HOST_MEMORY_MB={HOST_MEMORY_MB} {} {}\n  replay:  \
                 ALPENGLOW_CLI_PROPTEST_REPLAY=0x{id:016x} cargo test --test cli_property cli_options_property",
                case.command.words().join(" "),
                result.seconds,
                result.peak_rss >> 20,
                env!("CARGO_BIN_EXE_alpenglow"),
                shell_line(&case.args[..]),
            );
            Verdict::Failed(line)
        }
    };
    let _ = std::fs::remove_dir_all(&scratch);
    let _ = std::fs::remove_dir_all(&case.out_dir);
    verdict
}

#[test]
fn cli_options_property() {
    let root = std::env::temp_dir().join(format!("alpenglow-cli-proptest-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let fixtures = Fixtures::create(&root.join("fixtures"));
    if let Some(id) = env_u64("ALPENGLOW_CLI_PROPTEST_REPLAY") {
        let case = generate(id, &fixtures, &root);
        eprintln!("replaying case 0x{id:016x}: {}", shell_line(&case.args[..]));
        let verdict = run_case(id, &fixtures, &root);
        let _ = std::fs::remove_dir_all(&root);
        match verdict {
            Verdict::Failed(line) => panic!("{line}"),
            Verdict::Ok => eprintln!("exit 0, outputs valid"),
            Verdict::Error => eprintln!("a one-line error naming the culprit"),
        }
        return;
    }
    let cases = env_u64("ALPENGLOW_CLI_PROPTEST_CASES").unwrap_or(100);
    let budget = env_u64("ALPENGLOW_CLI_PROPTEST_SECONDS").map(Duration::from_secs);
    let base = env_u64("ALPENGLOW_CLI_PROPTEST_SEED").unwrap_or(0x0a1b_ec11);
    let started = Instant::now();
    let next = AtomicU64::new(0);
    let counts: [AtomicU64; 2] = Default::default();
    let failures: Mutex<Vec<String>> = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let n = next.fetch_add(1, Ordering::Relaxed);
                if n >= cases && !budget.is_some_and(|b| started.elapsed() < b) {
                    break;
                }
                if n > 0 && n % 50 == 0 {
                    eprintln!("cli property: case {n} at {:.0} s", started.elapsed().as_secs_f64());
                }
                // Mixed first, so that seeds 1 and 2 share no case.
                let id = splitmix64(splitmix64(base).wrapping_add(n));
                match run_case(id, &fixtures, &root) {
                    Verdict::Ok => counts[0].fetch_add(1, Ordering::Relaxed),
                    Verdict::Error => counts[1].fetch_add(1, Ordering::Relaxed),
                    Verdict::Failed(line) => {
                        eprintln!("FAILED {line}");
                        failures.lock().unwrap().push(line);
                        0
                    }
                };
            });
        }
    });
    let _ = std::fs::remove_dir_all(&root);
    let failures = failures.into_inner().unwrap();
    let [ok, errors] = counts.map(|c| c.into_inner());
    eprintln!(
        "cli property: {} cases in {:.0} s (seed 0x{base:x}): {ok} exit 0 with valid outputs, {errors} \
         one-line errors naming the culprit, {} failures",
        ok + errors + failures.len() as u64,
        started.elapsed().as_secs_f64(),
        failures.len()
    );
    assert!(
        failures.is_empty(),
        "{} case(s) failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
