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

    /// The CLI and the front-door example are clients of the public API
    /// only: neither reaches into `alpenglow::bench`.
    #[test]
    fn the_cli_and_drive_do_not_use_bench() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut files = vec![root.join("src/main.rs"), root.join("examples/drive.rs")];
        for entry in std::fs::read_dir(root.join("src/cli")).unwrap() {
            files.push(entry.unwrap().path());
        }
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
