//! Helpers of the texture atlas tests: a driver's view of the real DEM and
//! the comparison of atlas texels with the CPU twin of the generation
//! shaders (`crate::texturing::reference`).

use std::collections::HashSet;

use crate::renderer::{Camera, Scene};
use crate::surface::bspline::sample_bspline;
use crate::terrain::geometry_image::TerrainSettings;
use crate::texturing::page_table::{PageEntry, PageTable};
use crate::texturing::reference::{srgb8, ReferenceSurface};
use glam::{DVec2, DVec3};

/// Largest difference of one 8-bit sRGB channel between the atlas and the
/// CPU twin: the GPU computes in f32, stores colour in half floats between
/// passes and rounds once more.
pub const MAX_CODE_DIFFERENCE: i32 = 2;

/// A driver's view 2 m above the ground of the Jacksboro DEM at
/// (15 000, 12 000) m, looking along `look` (metres, xy) at 1 m above the
/// ground there, 60° vertical field of view.
pub fn ground_camera(scene: &Scene, look: DVec2) -> Camera {
    let ground = |p: DVec2| sample_bspline(&scene.heights, p.x, p.y);
    let eye = DVec2::new(15000.0, 12000.0);
    let target = eye + look;
    Camera {
        eye: eye.extend(ground(eye) + 2.0),
        target: target.extend(ground(target) + 1.0),
        up: DVec3::Z,
        fov_y_deg: 60.0,
        near: 0.1,
        far: 100000.0,
    }
}

/// Compares a 6×6 grid of inner texels of every tile `table` draws from
/// (colour textures `atlas` of `atlas_size`² texels, as read back) with the
/// CPU twin; panics on a channel off by more than [`MAX_CODE_DIFFERENCE`].
/// Returns the number of tiles compared.
pub fn check_texels_against_cpu(
    name: &str,
    scene: &Scene,
    atlas: &[Vec<u8>],
    atlas_size: u32,
    table: &PageTable,
) -> usize {
    let reference = ReferenceSurface::new(
        &scene.heights,
        &scene.layers,
        &scene.input_maps,
        TerrainSettings::default().noise_seed,
    )
    .expect("reference");
    let mut seen = HashSet::new();
    let entries: Vec<&PageEntry> = (table.entries.iter())
        .filter(|e| seen.insert((e.texture, e.atlas_origin.map(f32::to_bits))))
        .collect();
    let (mut worst, mut total, mut count) = (0i32, 0i64, 0i64);
    for e in &entries {
        let inner = e.inner_texels as u32;
        let spacing = DVec2::from(e.node_size.map(f64::from)) / f64::from(inner);
        for b in 0..6 {
            for a in 0..6 {
                let (i, j) = (a * (inner - 1) / 5, b * (inner - 1) / 5);
                let xy =
                    DVec2::from(e.node_min.map(f64::from)) + (DVec2::new(f64::from(i), f64::from(j)) + 0.5) * spacing;
                let cpu = srgb8(reference.evaluate(xy, spacing.max_element()).color);
                let (x, y) = (e.atlas_origin[0] as u32 + i, e.atlas_origin[1] as u32 + j);
                let texel = ((y * atlas_size + x) * 4) as usize;
                let gpu = &atlas[e.texture as usize][texel..texel + 3];
                for c in 0..3 {
                    let d = (i32::from(gpu[c]) - i32::from(cpu[c])).abs();
                    worst = worst.max(d);
                    total += i64::from(d);
                    count += 1;
                }
                assert!(
                    (0..3).all(|c| (i32::from(gpu[c]) - i32::from(cpu[c])).abs() <= MAX_CODE_DIFFERENCE),
                    "{name}: texel ({x}, {y}) of atlas texture {} at world {xy}: GPU {gpu:?}, CPU {cpu:?}",
                    e.texture
                );
            }
        }
    }
    eprintln!(
        "{name}: {} tiles, {} channels compared, largest difference {worst}, mean {:.4} code values",
        entries.len(),
        count,
        total as f64 / count.max(1) as f64
    );
    entries.len()
}

/// The colour textures `atlas` (of `atlas_size`² texels) with only the
/// inner texels of the tiles `table` draws from kept, the rest black:
/// slots no tile uses hold whatever the memory held. Textures without a
/// used tile are left out; returns `(texture index, RGBA8)` pairs.
pub fn used_tiles(atlas: &[Vec<u8>], atlas_size: u32, table: &PageTable) -> Vec<(usize, Vec<u8>)> {
    let mut out: Vec<Option<Vec<u8>>> = vec![None; atlas.len()];
    for e in &table.entries {
        let t = e.texture as usize;
        let image = out[t].get_or_insert_with(|| (0..atlas_size * atlas_size).flat_map(|_| [0, 0, 0, 255]).collect());
        let (x0, y0, n) = (
            e.atlas_origin[0] as u32,
            e.atlas_origin[1] as u32,
            e.inner_texels as u32,
        );
        for y in y0..(y0 + n).min(atlas_size) {
            let row = ((y * atlas_size + x0) * 4) as usize..((y * atlas_size + (x0 + n).min(atlas_size)) * 4) as usize;
            image[row.clone()].copy_from_slice(&atlas[t][row]);
        }
    }
    out.into_iter()
        .enumerate()
        .filter_map(|(i, t)| t.map(|t| (i, t)))
        .collect()
}
