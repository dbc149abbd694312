//! With the feature `hot-reload`: links the static glslang and SPIRV-Tools
//! archives shaderc needs into this package's binaries and tests; the
//! arguments come from `alpenglow-shader-compiler`'s build script
//! (`rustc-link-arg` does not reach a dependent's targets by itself).
fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=DEP_ALPENGLOW_GLSLANG_LINK_ARGS");
    for arg in std::env::var("DEP_ALPENGLOW_GLSLANG_LINK_ARGS")
        .unwrap_or_default()
        .split_whitespace()
    {
        println!("cargo:rustc-link-arg={arg}");
    }
}
