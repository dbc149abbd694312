//! Links the static glslang and SPIRV-Tools archives that Debian's
//! `libshaderc_combined.a` leaves out (it only bundles shaderc itself), and
//! passes the same arguments on to the packages that depend on this one
//! (`rustc-link-arg` only reaches this package's own binaries and tests):
//! their build scripts read them from `DEP_ALPENGLOW_GLSLANG_LINK_ARGS`
//! (`build.rs` of the root crate and `tools/build.rs`).
fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let args: &[&str] = if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        &[
            "-Wl,--start-group",
            "-l:libglslang.a",
            "-l:libMachineIndependent.a",
            "-l:libOSDependent.a",
            "-l:libGenericCodeGen.a",
            "-l:libOGLCompiler.a",
            "-l:libSPIRV.a",
            "-l:libSPIRV-Tools-opt.a",
            "-l:libSPIRV-Tools.a",
            "-Wl,--end-group",
        ]
    } else {
        &[]
    };
    for arg in args {
        println!("cargo:rustc-link-arg={arg}");
    }
    // Metadata for dependents' build scripts (space-separated).
    println!("cargo:link_args={}", args.join(" "));
}
