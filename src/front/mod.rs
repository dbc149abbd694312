//! The front door's own code: the few constructors and helpers that the
//! crate root re-exports and that no technique owns.

pub(crate) mod scene;

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// The modules the crate root may declare `pub`: the documented front
    /// door ([`crate::files`], [`crate::tools`]) and the hidden
    /// [`crate::bench`]. Any other `pub mod` would publish internals.
    const PUBLIC_MODULES: [&str; 3] = ["bench", "files", "tools"];

    #[test]
    fn the_crate_root_publishes_only_the_front_door_modules() {
        let lib = include_str!("../lib.rs");
        let public: Vec<&str> = lib
            .lines()
            .filter_map(|l| l.trim().strip_prefix("pub mod "))
            .map(|l| l.trim_end_matches(';').trim())
            .collect();
        assert_eq!(public, PUBLIC_MODULES, "pub mod in src/lib.rs");
        for line in lib.lines().map(str::trim) {
            let glob = line.starts_with("pub use") && line.ends_with("::*;");
            assert!(!glob, "a glob re-export at the root publishes a whole module: {line}");
        }
    }

    /// Every client of the crate uses only the front door: the CLI, the
    /// examples, the integration tests and the Python and C bindings never
    /// reach into `alpenglow::bench` (only `benchmarks/` may; the private
    /// modules the compiler already refuses).
    #[test]
    fn clients_use_only_the_front_door() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = vec![root.join("src/main.rs")];
        for folder in ["src/cli", "examples", "tests", "python/src", "capi/src", "capi/tests"] {
            crate::test_support::rust_files(&root.join(folder), &mut files);
        }
        assert!(files.len() > 40, "only {} client files found", files.len());
        for file in files {
            let text = std::fs::read_to_string(&file).unwrap();
            assert!(
                !text.contains("alpenglow::bench"),
                "{} uses alpenglow::bench",
                file.display()
            );
        }
    }
}
