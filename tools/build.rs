//! Links the static glslang and SPIRV-Tools archives that Debian's
//! `libshaderc_combined.a` leaves out (it only bundles shaderc itself).
fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("linux") {
        for arg in [
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
        ] {
            println!("cargo:rustc-link-arg={arg}");
        }
    }
}
