//! Compiler and freshness-check behaviour on throwaway shader trees.

use alpenglow_tools::{check, compile, compile_all, shader_sources, spirv_path};
use std::fs;
use std::path::PathBuf;

/// A unique temporary repo with `glsl/` and `spirv/`, removed on drop.
struct Repo(PathBuf);

impl Repo {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("alpenglow-tools-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(dir.join("glsl")).unwrap();
        Repo(dir)
    }
    fn glsl(&self) -> PathBuf {
        self.0.join("glsl")
    }
    fn spirv(&self) -> PathBuf {
        self.0.join("spirv")
    }
    fn write(&self, rel: &str, text: &str) -> PathBuf {
        let path = self.glsl().join(rel);
        fs::create_dir_all(path.parent().unwrap()).unwrap();
        fs::write(&path, text).unwrap();
        path
    }
    fn check(&self) -> Vec<String> {
        check(&self.glsl(), &self.spirv()).unwrap()
    }
}

impl Drop for Repo {
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.0);
    }
}

const COMMON: &str = "const float SCALE = 2.0;\n";

fn comp(body: &str) -> String {
    format!(
        "#version 460\n#include \"common.glsl\"\nlayout(local_size_x = 64) in;\n\
         layout(set = 0, binding = 0) buffer Data {{ float v[]; }};\n\
         void main() {{ uint i = gl_GlobalInvocationID.x; v[i] = {body}; }}\n"
    )
}

/// A tree with a nested compute shader, a vertex shader and a shared include.
fn sample(name: &str) -> (Repo, PathBuf) {
    let repo = Repo::new(name);
    repo.write("common.glsl", COMMON);
    let grid = repo.write("terrain/grid.comp", &comp("v[i] * SCALE"));
    repo.write(
        "tri.vert",
        "#version 460\nvoid main() { gl_Position = vec4(float(gl_VertexIndex), 0.0, 0.0, 1.0); }\n",
    );
    (repo, grid)
}

#[test]
fn sources_are_sorted_and_skip_includes() {
    let (repo, grid) = sample("sources");
    let sources = shader_sources(&repo.glsl()).unwrap();
    assert_eq!(sources, vec![grid.clone(), repo.glsl().join("tri.vert")]);
    assert_eq!(
        spirv_path(&repo.glsl(), &repo.spirv(), &grid),
        repo.spirv().join("terrain/grid.comp.spv")
    );
}

#[test]
fn compiled_module_is_valid_spirv_1_6_and_fresh() {
    let (repo, grid) = sample("fresh");
    assert_eq!(repo.check().len(), 2, "both modules start missing");
    assert_eq!(compile_all(&repo.glsl(), &repo.spirv()).unwrap(), 2);
    let bytes = fs::read(repo.spirv().join("terrain/grid.comp.spv")).unwrap();
    assert_eq!(&bytes[0..4], &0x0723_0203u32.to_le_bytes(), "SPIR-V magic");
    assert_eq!(&bytes[4..8], &0x0001_0600u32.to_le_bytes(), "SPIR-V 1.6");
    assert_eq!(bytes, compile(&repo.glsl(), &grid).unwrap(), "deterministic");
    assert!(repo.check().is_empty(), "{:?}", repo.check());
    assert_eq!(
        compile_all(&repo.glsl(), &repo.spirv()).unwrap(),
        0,
        "nothing rewritten"
    );
}

#[test]
fn edited_source_is_stale() {
    let (repo, _) = sample("stale");
    compile_all(&repo.glsl(), &repo.spirv()).unwrap();
    repo.write("terrain/grid.comp", &comp("v[i] + SCALE"));
    let problems = repo.check();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].starts_with("stale:") && problems[0].contains("grid.comp.spv"));
    assert_eq!(compile_all(&repo.glsl(), &repo.spirv()).unwrap(), 1);
    assert!(repo.check().is_empty());
}

#[test]
fn include_change_makes_dependents_stale() {
    let (repo, _) = sample("include");
    compile_all(&repo.glsl(), &repo.spirv()).unwrap();
    repo.write("common.glsl", "const float SCALE = 3.0;\n");
    let problems = repo.check();
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].starts_with("stale:") && problems[0].contains("grid.comp.spv"));
}

#[test]
fn nested_include_resolves_relative_then_root() {
    let repo = Repo::new("nested");
    repo.write("common.glsl", COMMON);
    // `local.glsl` is found next to the includer; `common.glsl` from the root.
    repo.write("a/local.glsl", "#include \"common.glsl\"\nconst float K = SCALE;\n");
    let src = repo.write("a/b.comp", &comp("K").replace("common.glsl", "local.glsl"));
    compile(&repo.glsl(), &src).unwrap();
}

#[test]
fn orphan_and_missing_modules_are_reported() {
    let (repo, _) = sample("orphan");
    compile_all(&repo.glsl(), &repo.spirv()).unwrap();
    fs::remove_file(repo.spirv().join("tri.vert.spv")).unwrap();
    fs::create_dir_all(repo.spirv().join("old")).unwrap();
    fs::write(repo.spirv().join("old/gone.frag.spv"), b"junk").unwrap();
    let problems = repo.check();
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(problems[0].starts_with("missing:") && problems[0].contains("tri.vert.spv"));
    assert!(problems[1].starts_with("orphan:") && problems[1].contains("gone.frag.spv"));
    assert_eq!(compile_all(&repo.glsl(), &repo.spirv()).unwrap(), 1);
    assert!(!repo.spirv().join("old").exists(), "empty orphan dir removed");
    assert!(repo.check().is_empty());
}

#[test]
fn syntax_error_names_file_and_line() {
    let repo = Repo::new("syntax");
    let src = repo.write("broken/bad.frag", "#version 460\nvoid main() {\n  oops\n}\n");
    let err = format!("{:#}", compile(&repo.glsl(), &src).unwrap_err());
    assert!(err.contains("glsl/broken/bad.frag:"), "{err}");
    assert!(err.contains("error"), "{err}");
    let err = format!("{:#}", compile_all(&repo.glsl(), &repo.spirv()).unwrap_err());
    assert!(err.contains("bad.frag"), "{err}");
    assert!(!repo.spirv().exists(), "nothing written on failure");
}

#[test]
fn missing_include_is_an_error() {
    let repo = Repo::new("noinclude");
    let src = repo.write("x.comp", &comp("1.0"));
    let err = format!("{:#}", compile(&repo.glsl(), &src).unwrap_err());
    assert!(err.contains("common.glsl"), "{err}");
}
