//! Progress of long CPU work on stderr (`synth fill`, `synth transition`,
//! `spt build`), drawn as the sky-light bake's: the library reports through
//! a callback, the command line draws an indicatif bar. indicatif draws
//! only when stderr is a terminal, so a pipe or a file sees nothing; on a
//! terminal the bar is redrawn every [`TICK`] (spinner and elapsed time)
//! even while the library has nothing new to report, so no phase is silent.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

/// How often a bar is redrawn on a terminal whatever the work reports.
pub const TICK: Duration = Duration::from_millis(250);

/// A bar of `len` steps: `{spinner} [elapsed] {bar} {template}`, where
/// `template` holds the bar's position fields (`{pos}/{len} samples`,
/// `{percent}%`), followed by the estimated time left.
pub fn bar(len: u64, template: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} [{{elapsed_precise}}] {{bar:40}} {template} (eta {{eta}})"
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.enable_steady_tick(TICK);
    bar
}

/// A spinner for a phase that reports no fraction: `{spinner} [elapsed] message`.
pub fn spinner(message: &str) -> ProgressBar {
    let spinner = ProgressBar::new_spinner();
    spinner.set_style(
        ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    spinner.set_message(message.to_string());
    spinner.enable_steady_tick(TICK);
    spinner
}

/// Runs `work` with a [`spinner`] showing `message`, then clears it.
pub fn phase<T>(message: &str, work: impl FnOnce() -> T) -> T {
    let spinner = spinner(message);
    let out = work();
    spinner.finish_and_clear();
    out
}
