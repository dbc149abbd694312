//! Links the static glslang and SPIRV-Tools archives that Debian's
//! `libshaderc_combined.a` leaves out: the arguments come from
//! `alpenglow-shader-compiler`'s build script (`rustc-link-arg` does not
//! reach a dependent's binaries and tests by itself).
fn main() {
    println!("cargo:rerun-if-env-changed=DEP_ALPENGLOW_GLSLANG_LINK_ARGS");
    for arg in std::env::var("DEP_ALPENGLOW_GLSLANG_LINK_ARGS")
        .unwrap_or_default()
        .split_whitespace()
    {
        println!("cargo:rustc-link-arg={arg}");
    }
}
