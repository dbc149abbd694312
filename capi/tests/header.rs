//! Fails when the checked-in `include/alpenglow.h` is not what cbindgen
//! generates from this crate now (like the SPIR-V freshness test).

use std::path::{Path, PathBuf};

/// The command that rewrites the header.
const FIX_COMMAND: &str = "ALPENGLOW_C_REGENERATE=1 cargo test -p alpenglow-c --test header";

fn header_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../include/alpenglow.h")
}

fn generate() -> String {
    let crate_dir = env!("CARGO_MANIFEST_DIR");
    let config = cbindgen::Config::from_file(Path::new(crate_dir).join("cbindgen.toml"))
        .unwrap_or_else(|e| panic!("capi/cbindgen.toml: {e}"));
    let bindings = cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .unwrap_or_else(|e| panic!("cbindgen failed on capi/src: {e}"));
    let mut bytes = Vec::new();
    bindings.write(&mut bytes);
    String::from_utf8(bytes).expect("cbindgen writes UTF-8")
}

#[test]
fn header_is_fresh() {
    let generated = generate();
    let path = header_path();
    if std::env::var_os("ALPENGLOW_C_REGENERATE").is_some() {
        std::fs::write(&path, &generated).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    if checked_in != generated {
        let line = (checked_in.lines().zip(generated.lines()))
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| checked_in.lines().count().min(generated.lines().count()));
        panic!(
            "include/alpenglow.h is out of date with capi/src (first difference at line {}); \
             regenerate it with `{FIX_COMMAND}`",
            line + 1
        );
    }
}
