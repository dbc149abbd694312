//! Compiles `glsl/` into `spirv/`, or with `--check` verifies that the
//! checked-in SPIR-V modules are up to date.
//!
//! Exit status: 0 on success, 1 when `--check` finds problems, 2 when a
//! shader fails to compile (or on I/O errors).

use alpenglow_tools::{check, compile_all, default_glsl_root, default_spirv_root, FIX_COMMAND};
use clap::Parser;
use std::path::PathBuf;
use std::process::ExitCode;

/// Offline GLSL -> SPIR-V compiler for alpenglow.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Only verify; list stale, missing and orphan modules and exit 1 if any.
    #[arg(long)]
    check: bool,
    /// Shader source root (default: <repo>/glsl).
    #[arg(long)]
    glsl: Option<PathBuf>,
    /// SPIR-V output root (default: <repo>/spirv).
    #[arg(long)]
    spirv: Option<PathBuf>,
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(args: Args) -> anyhow::Result<ExitCode> {
    let glsl = args.glsl.unwrap_or_else(default_glsl_root);
    let spirv = args.spirv.unwrap_or_else(default_spirv_root);
    if args.check {
        let problems = check(&glsl, &spirv)?;
        for problem in &problems {
            println!("{problem}");
        }
        if !problems.is_empty() {
            eprintln!("{} problem(s); run `{FIX_COMMAND}`", problems.len());
            return Ok(ExitCode::FAILURE);
        }
        eprintln!("all SPIR-V modules are up to date");
    } else {
        let written = compile_all(&glsl, &spirv)?;
        eprintln!("{written} SPIR-V module(s) written to {}", spirv.display());
    }
    Ok(ExitCode::SUCCESS)
}
