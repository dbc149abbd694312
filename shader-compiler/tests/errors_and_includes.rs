//! One line per compile error, naming file and line; the include scan
//! that hot reload uses to find a changed include's shaders.

use alpenglow_shader_compiler::{compile_module, includes};
use std::fs;
use std::path::PathBuf;

/// A throwaway `glsl/` tree, removed on drop.
struct Tree(PathBuf);

impl Tree {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("alpenglow-shader-compiler-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(dir.join("glsl/include")).unwrap();
        Tree(dir)
    }
    fn write(&self, rel: &str, text: &str) -> PathBuf {
        let path = self.0.join("glsl").join(rel);
        fs::write(&path, text).unwrap();
        path.canonicalize().unwrap()
    }
}

impl Drop for Tree {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

#[test]
fn two_errors_are_two_lines_naming_file_and_line() {
    let tree = Tree::new("errors");
    let shader = tree.write(
        "bad.comp",
        "#version 460\nlayout(local_size_x = 1) in;\nvoid main() {\n  float a = b;\n  float c = d;\n}\n",
    );
    let error = compile_module(&tree.0.join("glsl"), &shader).unwrap_err();
    let lines = error.lines();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert!(lines[0].starts_with("glsl/bad.comp:4: error:"), "{lines:?}");
    assert!(lines[1].starts_with("glsl/bad.comp:5: error:"), "{lines:?}");
}

#[test]
fn includes_are_found_transitively() {
    let tree = Tree::new("includes");
    let inner = tree.write("include/inner.glsl", "const float K = 2.0;\n");
    let outer = tree.write("include/outer.glsl", "#include \"inner.glsl\"\n");
    let other = tree.write("include/other.glsl", "const float L = 1.0;\n");
    let shader = tree.write(
        "a.comp",
        "#version 460\n#include \"include/outer.glsl\"\nlayout(local_size_x = 1) in;\nvoid main() {}\n",
    );
    let found = includes(&tree.0.join("glsl"), &shader);
    assert!(found.contains(&inner) && found.contains(&outer), "{found:?}");
    assert!(!found.contains(&other), "{found:?}");
    assert!(compile_module(&tree.0.join("glsl"), &shader).is_ok());
}
