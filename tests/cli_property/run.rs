//! Runs a case's command line under a time and memory bound and judges
//! what came back.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::case::{Case, Output};

/// Host memory the binary's memory model may plan with
/// (`ALPENGLOW_HOST_MEMORY_MB`): counts that need more are refused early.
pub const HOST_MEMORY_MB: &str = "1024";
/// Resident memory at which a case is killed and fails.
pub const RSS_CAP_BYTES: u64 = 4 << 30;
/// Wall time at which a case is killed and fails.
pub const TIMEOUT: Duration = Duration::from_secs(60);

/// How a run ended.
#[derive(Debug)]
pub struct Run {
    pub code: Option<i32>,
    pub signal: Option<i32>,
    pub stderr: String,
    pub peak_rss: u64,
    pub seconds: f64,
    /// Why the harness killed it (time or memory), if it did.
    pub killed: Option<String>,
}

/// `VmHWM` (peak resident set) of process `pid` in bytes, if readable.
fn peak_rss(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Runs the binary with `case.args`, stdout and stderr into files of the
/// case folder; kills it past [`TIMEOUT`] or [`RSS_CAP_BYTES`].
pub fn run(case: &Case, scratch: &Path) -> Run {
    use std::os::unix::process::ExitStatusExt;
    std::fs::create_dir_all(scratch).unwrap();
    std::fs::create_dir_all(&case.out_dir).unwrap();
    let (out_path, err_path) = (scratch.join("stdout"), scratch.join("stderr"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_alpenglow"))
        .args(&case.args[..])
        .env("ALPENGLOW_HOST_MEMORY_MB", HOST_MEMORY_MB)
        .env(
            "XDG_CACHE_HOME",
            Path::new(env!("CARGO_MANIFEST_DIR")).join("target/test-cache"),
        )
        .env_remove("RUST_LOG")
        .env_remove("RUST_BACKTRACE")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", env!("CARGO_BIN_EXE_alpenglow")));
    let started = Instant::now();
    let mut peak = 0;
    let mut killed = None;
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        peak = peak.max(peak_rss(child.id()).unwrap_or(0));
        if killed.is_none() {
            if peak > RSS_CAP_BYTES {
                killed = Some(format!(
                    "resident memory {} MiB > {} MiB",
                    peak >> 20,
                    RSS_CAP_BYTES >> 20
                ));
            } else if started.elapsed() > TIMEOUT {
                killed = Some(format!("still running after {} s", TIMEOUT.as_secs()));
            }
            if killed.is_some() {
                let _ = child.kill();
            }
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let read = |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default()).into_owned();
    Run {
        code: status.code(),
        signal: status.signal(),
        stderr: read(&err_path),
        peak_rss: peak,
        seconds: started.elapsed().as_secs_f64(),
        killed,
    }
}

/// What is wrong with a run, by class.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Problem {
    Panic,
    Signal,
    Timeout,
    Memory,
    /// stderr is not log lines and one `error:` line.
    Shape,
    /// The error names no option or file of the command line.
    Culprit,
    /// Files left behind by a failed command.
    HalfWritten,
    /// Exit 0 with a missing or invalid output.
    BadOutput,
    /// Exit 0 though a numeric option was NaN.
    AcceptedNan,
}

/// The last `error:` line of a failed run.
pub fn error_line(run: &Run) -> Option<&str> {
    run.stderr.lines().rev().map(str::trim).find(|l| !l.is_empty())
}

/// Judges `run` of `case`: None when it passes, else the class and why.
pub fn judge(case: &Case, run: &Run) -> Option<(Problem, String)> {
    if let Some(why) = &run.killed {
        let p = if why.starts_with("resident") {
            Problem::Memory
        } else {
            Problem::Timeout
        };
        return Some((p, why.clone()));
    }
    if run.code == Some(101) || run.stderr.contains("panicked") {
        return Some((Problem::Panic, last_lines(&run.stderr)));
    }
    if let Some(sig) = run.signal {
        return Some((
            Problem::Signal,
            format!("killed by signal {sig}: {}", last_lines(&run.stderr)),
        ));
    }
    if run.code == Some(0) {
        if let Err(why) = check_outputs(case) {
            return Some((Problem::BadOutput, why));
        }
        if let Some((flag, v)) = case.varied.iter().find(|(_, v)| v.to_lowercase() == "nan") {
            return Some((Problem::AcceptedNan, format!("{flag} {v} was accepted")));
        }
        return None;
    }
    if let Err(why) = check_shape(&run.stderr) {
        return Some((Problem::Shape, why));
    }
    let line = error_line(run).unwrap_or("");
    if let Err(why) = check_culprit(case, line) {
        return Some((Problem::Culprit, why));
    }
    let left = left_behind(&case.out_dir);
    if !left.is_empty() {
        return Some((Problem::HalfWritten, format!("files left behind: {left:?} ({line})")));
    }
    None
}

fn last_lines(stderr: &str) -> String {
    let lines: Vec<&str> = stderr.lines().collect();
    lines[lines.len().saturating_sub(6)..].join(" | ")
}

/// Log lines (`[WARN  module] message`) followed by one `error: ` line.
fn check_shape(stderr: &str) -> Result<(), String> {
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    let Some((last, before)) = lines.split_last() else {
        return Err("failed with nothing on stderr".into());
    };
    if !last.starts_with("error: ") || last.trim() == "error:" {
        return Err(format!("the last stderr line is not an error: {}", last_lines(stderr)));
    }
    if let Some(odd) = before
        .iter()
        .find(|l| !(l.starts_with("[WARN") || l.starts_with("[INFO")))
    {
        return Err(format!(
            "stderr has a line that is neither a log line nor the error: {odd:?}"
        ));
    }
    Ok(())
}

/// The option groups an error line names (`--near/--far` is one group),
/// in order, without `--help`.
pub fn named_flags(line: &str) -> Vec<Vec<String>> {
    let bytes = line.as_bytes();
    let mut groups: Vec<Vec<String>> = Vec::new();
    let mut i = 0;
    let mut joined = false;
    while i + 2 < bytes.len() {
        let starts = bytes[i] == b'-'
            && bytes[i + 1] == b'-'
            && bytes[i + 2].is_ascii_lowercase()
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'-'));
        if !starts {
            i += 1;
            continue;
        }
        let mut j = i + 2;
        while j < bytes.len() && (bytes[j].is_ascii_lowercase() || bytes[j].is_ascii_digit() || bytes[j] == b'-') {
            j += 1;
        }
        let flag = line[i..j].to_string();
        if flag != "--help" {
            match (joined, groups.last_mut()) {
                (true, Some(g)) => g.push(flag),
                _ => groups.push(vec![flag]),
            }
        }
        joined = bytes.get(j) == Some(&b'/');
        i = j;
    }
    groups
}

/// The error must name what the command line gave: the first thing it
/// names (an option group such as `--near/--far`, or a file or positional
/// value) must be on the command line; a later option may be a remedy
/// ("set --height-scale").
fn check_culprit(case: &Case, line: &str) -> Result<(), String> {
    let flags = case.flags();
    let first_flag = named_flags(line).into_iter().next().map(|group| {
        let at = line.find(group[0].as_str()).unwrap_or(usize::MAX);
        (at, group)
    });
    let first_file = case
        .files
        .iter()
        .filter_map(|f| {
            let name = Path::new(f).file_name().map(|n| n.to_string_lossy().into_owned());
            line.find(f.as_str()).or_else(|| name.and_then(|n| line.find(&n)))
        })
        .min();
    match (first_flag, first_file) {
        (Some((at, _)), Some(file)) if file < at => Ok(()),
        (Some((_, group)), _) if group.iter().any(|f| flags.contains(&f.as_str())) => Ok(()),
        (Some((_, group)), _) => Err(format!("names {} (not on the command line): {line}", group.join("/"))),
        (None, Some(_)) => Ok(()),
        (None, None) => Err(format!("names no option or file of the command line: {line}")),
    }
}

/// Files under `dir`, recursively (hidden staging folders included).
fn left_behind(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    if let Ok(entries) = std::fs::read_dir(dir) {
        for e in entries.flatten() {
            found.push(e.file_name().to_string_lossy().into_owned());
        }
    }
    found.sort();
    found
}

/// Every output of a successful run exists and decodes.
fn check_outputs(case: &Case) -> Result<(), String> {
    for output in &case.outputs {
        check_output(case, output)?;
    }
    Ok(())
}

fn check_output(case: &Case, output: &Output) -> Result<(), String> {
    use alpenglow::files::load_heightmap;
    use alpenglow::HeightmapOptions;
    let fail = |p: &Path, why: String| Err(format!("{}: {why}", p.display()));
    match output {
        Output::Png(p) => match image::open(p) {
            Ok(img) if img.width() > 0 && img.height() > 0 => Ok(()),
            Ok(_) => fail(p, "an empty image".into()),
            Err(e) => fail(p, format!("does not decode: {e}")),
        },
        Output::Exr(p) => match exr::prelude::read_all_flat_layers_from_file(p) {
            Ok(img) if !img.layer_data.is_empty() => Ok(()),
            Ok(_) => fail(p, "no layer".into()),
            Err(e) => fail(p, format!("does not open: {e}")),
        },
        Output::Json(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            match serde_json::from_str::<serde_json::Value>(&text) {
                Ok(_) => Ok(()),
                Err(e) => fail(p, format!("does not parse: {e}")),
            }
        }
        Output::Frames(dir) => {
            let frames = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            let mut n = 0;
            for f in frames.flatten() {
                check_output(case, &Output::Png(f.path()))?;
                n += 1;
            }
            if n == 0 {
                return fail(dir, "no frame".into());
            }
            Ok(())
        }
        Output::Spt(p) => match alpenglow::files::read_spt(p) {
            Ok(_) => Ok(()),
            Err(e) => fail(p, format!("does not load: {e}")),
        },
        Output::Height(p) => {
            // Read back with the command's own height mapping.
            let given = |flag: &str, default: f32| {
                let at = case.args.iter().position(|a| a == flag);
                at.and_then(|i| case.args.get(i + 1)?.parse().ok()).unwrap_or(default)
            };
            let opts = HeightmapOptions {
                spacing: Some(alpenglow::glam::DVec2::ONE),
                scale: given("--height-scale", 1.0),
                offset: given("--height-offset", 0.0),
                ..HeightmapOptions::default()
            };
            // `synth grow` writes its `--size` (N or CxR), the others the input's 33².
            let size = case.args.iter().position(|a| a == "--size").and_then(|i| {
                let v = case.args.get(i + 1)?;
                let (c, r) = v.split_once('x').unwrap_or((v, v));
                Some((c.parse::<u32>().ok()?, r.parse::<u32>().ok()?))
            });
            let (columns, rows) = size.unwrap_or((33, 33));
            match load_heightmap(p, &opts) {
                Ok(f) if (f.columns, f.rows) == (columns, rows) => Ok(()),
                Ok(f) => fail(p, format!("{}×{} samples, not {columns}×{rows}", f.columns, f.rows)),
                Err(e) => fail(p, format!("does not load: {e}")),
            }
        }
        Output::Layers(p) => {
            let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
            match alpenglow::LayerTree::parse(&text, "written") {
                Ok(_) => Ok(()),
                Err(e) => fail(p, format!("does not parse: {e}")),
            }
        }
    }
}
