//! Compiles `capi/examples/render.c` against `include/alpenglow.h` and
//! both libraries this crate builds (`libalpenglow_c.so` and
//! `libalpenglow_c.a`, found next to this test binary in the target
//! directory: `cargo test` builds every crate type of the library), then
//! runs each build: the example renders under validation and exits non-zero
//! on any failed call, wrong output or validation message.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The directory cargo put this crate's libraries in (`target/<profile>`).
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    // target/<profile>/deps/c_example-<hash>
    let deps = exe.parent().expect("deps directory");
    for dir in [deps.parent().expect("profile directory"), deps] {
        if dir.join("libalpenglow_c.so").is_file() && dir.join("libalpenglow_c.a").is_file() {
            return dir.to_path_buf();
        }
    }
    panic!(
        "libalpenglow_c.so and libalpenglow_c.a not found next to {}: build them with `cargo build -p alpenglow-c`",
        exe.display()
    );
}

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Fails if the library is older than the test binary's own build of this
/// crate's sources (a stale library would test old code).
fn assert_fresh(library: &Path) {
    let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let newest_source = std::fs::read_dir(&src)
        .expect("capi/src")
        .filter_map(|e| e.ok().and_then(|e| modified(&e.path())))
        .max();
    if let (Some(lib), Some(source)) = (modified(library), newest_source) {
        assert!(
            lib >= source,
            "{} is older than capi/src: rebuild it with `cargo build -p alpenglow-c`",
            library.display()
        );
    }
}

/// Compiles the example with `link` (the library's linker arguments) into `name`.
fn compile(name: &str, link: &[String]) -> PathBuf {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let root = repo_root();
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&compiler)
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg("-I")
        .arg(root.join("include"))
        .arg(root.join("capi/examples/render.c"))
        .args(link)
        .arg("-o")
        .arg(&out)
        .status()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{compiler}`: {e}"));
    assert!(status.success(), "compiling render.c ({name}) failed: {status}");
    out
}

/// Runs the example; its output is shown on failure.
fn run(program: &Path) {
    let ppm = program.with_extension("ppm");
    let output = Command::new(program)
        .arg(&ppm)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", program.display()));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(
        output.status.success(),
        "{} failed ({}):\n{text}",
        program.display(),
        output.status
    );
    assert!(text.contains("validation messages: 0"), "{text}");
    let image = std::fs::read(&ppm).expect("the example writes its PPM");
    assert!(image.starts_with(b"P6\n64 48\n255\n"), "PPM header");
    assert_eq!(image.len(), "P6\n64 48\n255\n".len() + 64 * 48 * 3);
}

#[test]
fn c_example_runs_against_the_shared_library() {
    let dir = library_dir();
    assert_fresh(&dir.join("libalpenglow_c.so"));
    let link = [
        format!("-L{}", dir.display()),
        "-lalpenglow_c".into(),
        format!("-Wl,-rpath,{}", dir.display()),
        "-lm".into(),
    ];
    run(&compile("render_shared", &link));
}

#[test]
fn c_example_runs_against_the_static_library() {
    let dir = library_dir();
    let archive = dir.join("libalpenglow_c.a");
    assert_fresh(&archive);
    // The system libraries Rust's standard library needs (as printed by
    // `rustc --print native-static-libs` on Linux).
    let mut link = vec![archive.display().to_string()];
    link.extend(["-lgcc_s", "-lutil", "-lrt", "-lpthread", "-lm", "-ldl", "-lc"].map(String::from));
    let program = compile("render_static", &link);
    // Linked statically: the program needs no libalpenglow_c.so.
    let ldd = Command::new("ldd").arg(&program).output();
    if let Ok(ldd) = ldd {
        assert!(
            !String::from_utf8_lossy(&ldd.stdout).contains("alpenglow"),
            "static build links the .so"
        );
    }
    run(&program);
}
