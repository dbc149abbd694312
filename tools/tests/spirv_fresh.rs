//! Fails when the checked-in `spirv/` modules do not match `glsl/`.

use alpenglow_tools::{check, default_glsl_root, default_spirv_root, FIX_COMMAND};

#[test]
fn spirv_matches_glsl() {
    let problems = check(&default_glsl_root(), &default_spirv_root())
        .unwrap_or_else(|e| panic!("shader compilation failed: {e:#}"));
    assert!(
        problems.is_empty(),
        "SPIR-V modules are out of date with glsl/:\n  {}\nregenerate them with `{FIX_COMMAND}`",
        problems.join("\n  ")
    );
}
