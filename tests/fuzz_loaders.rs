//! Fuzz suite of every file loader (issue 15): mutated seed files from
//! `tests/data/fuzz/` must give a valid result or a one-line error naming
//! the file, never a panic, an abort or unbounded memory. See `fuzz/mod.rs`
//! for the environment variables and `docs/FUZZING.md` for longer runs.

mod fuzz;

use std::path::Path;

use alpenglow::files::{load_heightmap, load_keyframes, load_points_file, read_spt, write_spt, PointInput};
use alpenglow::tools::layers::{
    Constraint, MAX_BLUR_RADII, MAX_HEIGHT_BLUR, MAX_SAMPLES, MAX_VEGETATION_DENSITY, MAX_VEGETATION_SCALE,
};
use alpenglow::{HeightmapOptions, LayerTree, Rig};
use fuzz::mutate::{fix_png_crcs, reseal_spt, Kind};
use fuzz::{fuzz, no_fixup, regressions, Outcome, Target};

#[global_allocator]
static COUNTING: fuzz::alloc::Counting = fuzz::alloc::Counting;

fn heightmap(path: &Path) -> Outcome {
    let field = load_heightmap(path, &HeightmapOptions::default())?;
    let expected = field.columns as usize * field.rows as usize;
    if field.heights.len() != expected {
        return Ok(Err(format!("{} heights for {expected} samples", field.heights.len())));
    }
    Ok(field.validate(path).map_err(|e| e.to_string()))
}

fn points(path: &Path) -> Outcome {
    let input = load_points_file(path)?;
    let n = input.positions().len();
    let (normals, colors) = match &input {
        PointInput::Mesh(m) => {
            if m.triangles.is_empty() || m.triangles.iter().flatten().any(|&i| i as usize >= n) {
                return Ok(Err("no triangles, or an index out of range".into()));
            }
            (m.normals.as_ref().map(Vec::len), m.colors.as_ref().map(Vec::len))
        }
        PointInput::Points(p) => {
            if p.radii
                .as_ref()
                .is_some_and(|r| r.len() != n || r.iter().any(|r| !(r.is_finite() && *r > 0.0)))
            {
                return Ok(Err("bad radii".into()));
            }
            (p.normals.as_ref().map(Vec::len), p.colors.as_ref().map(Vec::len))
        }
    };
    if n == 0 || input.positions().iter().any(|p| !p.is_finite()) {
        return Ok(Err("no points, or a non-finite position".into()));
    }
    if normals.is_some_and(|k| k != n) || colors.is_some_and(|k| k != n) {
        return Ok(Err("attribute count differs from the point count".into()));
    }
    Ok(Ok(()))
}

fn spt(path: &Path) -> Outcome {
    let tree = read_spt(path)?;
    // The writer runs the same validation again.
    let copy = path.with_extension("copy.spt");
    let written = write_spt(&copy, &tree).map_err(|e| e.to_string());
    let _ = std::fs::remove_file(&copy);
    Ok(written)
}

fn layers(path: &Path) -> Outcome {
    let tree = LayerTree::load(path)?;
    let sampled_ok = |c: &Option<Constraint>| match c {
        Some(Constraint::Sampled(s)) => {
            s.min < s.max
                && (1..=MAX_SAMPLES).contains(&s.samples.len())
                && s.samples.iter().all(|v| (0.0..=1.0).contains(v))
        }
        _ => true,
    };
    let ok = !tree.layers.is_empty()
        && tree.blur_radii().len() <= MAX_BLUR_RADII
        && tree.layers.iter().all(|l| {
            let l = &l.layer;
            let constraints = [
                &l.altitude,
                &l.elevation,
                &l.slope,
                &l.inputs[0],
                &l.inputs[1],
                &l.inputs[2],
            ];
            l.color.is_finite()
                && l.color.min_element() >= 0.0
                && l.color.max_element() <= 1.0
                && constraints.into_iter().all(sampled_ok)
                && l.height_blur.map_or(true, |r| r > 0.0 && r <= MAX_HEIGHT_BLUR)
                && l.vegetation.iter().all(|v| {
                    (0.0..=MAX_VEGETATION_DENSITY).contains(&v.density)
                        && v.scale.0 > 0.0
                        && v.scale.0 <= v.scale.1
                        && v.scale.1 <= MAX_VEGETATION_SCALE
                })
        });
    Ok(if ok {
        Ok(())
    } else {
        Err("empty tree, a colour, sampled function, height_blur or vegetation table out of range".into())
    })
}

fn keyframes(path: &Path) -> Outcome {
    let camera_path = load_keyframes(path)?;
    if !(camera_path.duration().is_finite() && camera_path.duration() > 0.0) {
        return Ok(Err(format!("duration {}", camera_path.duration())));
    }
    Ok(camera_path.validate().map_err(|e| e.to_string()))
}

fn rig(path: &Path) -> Outcome {
    let rig = Rig::load(path)?;
    Ok(rig.specs((1, 1)).map(|_| ()).map_err(|e| e.to_string()))
}

fn target(corpus: &'static str, extension: &'static str, kind: Kind, load: fn(&Path) -> Outcome) -> Target {
    Target {
        corpus,
        extension,
        kind,
        fixup: no_fixup,
        load,
    }
}

#[test]
fn png_heightmap() {
    fuzz(&Target {
        fixup: fix_png_crcs,
        ..target("png", "png", Kind::Binary, heightmap)
    });
}

#[test]
fn geotiff_heightmap() {
    fuzz(&target("geotiff", "tif", Kind::Binary, heightmap));
}

#[test]
fn exr_heightmap() {
    fuzz(&target("exr", "exr", Kind::Binary, heightmap));
}

#[test]
fn input_map() {
    fuzz(&Target {
        fixup: fix_png_crcs,
        ..target("input_map", "png", Kind::Binary, heightmap)
    });
}

#[test]
fn ply() {
    fuzz(&target("ply", "ply", Kind::Text, points));
}

#[test]
fn obj() {
    fuzz(&target("obj", "obj", Kind::Text, points));
}

#[test]
fn spt_file() {
    fuzz(&Target {
        fixup: reseal_spt,
        ..target("spt", "spt", Kind::Binary, spt)
    });
}

#[test]
fn layers_toml() {
    fuzz(&target("layers", "toml", Kind::Text, layers));
}

#[test]
fn keyframes_toml() {
    fuzz(&target("keyframes", "toml", Kind::Text, keyframes));
}

#[test]
fn rig_toml() {
    fuzz(&target("rig", "toml", Kind::Text, rig));
}

/// Inputs AFL++ found (docs/FUZZING.md): EXR files whose data window makes
/// the decoder claim ~1.8 GB and seconds, and a PNG whose header makes it
/// abort on a failed allocation.
#[test]
fn afl_findings_stay_fixed() {
    assert_eq!(regressions(&target("exr", "exr", Kind::Binary, heightmap), "exr"), 3);
    assert_eq!(regressions(&target("png", "png", Kind::Binary, heightmap), "png"), 1);
    // A SampleFormat tag with no values panicked inside tiff 0.10.
    assert_eq!(
        regressions(&target("geotiff", "tif", Kind::Binary, heightmap), "geotiff"),
        1
    );
}
