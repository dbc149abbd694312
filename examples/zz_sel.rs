use alpenglow::io::heightmap::{load_heightmap, HeightmapOptions};
use alpenglow::texturing::atlas::TileCache;
use alpenglow::texturing::generation::TextureStreaming;
use alpenglow::texturing::quadtree::{select_tiles, HeightBounds, View};
use alpenglow::view::{frustum_planes, Camera};
use glam::DVec3;
use std::collections::BTreeMap;
fn main() {
    let o = HeightmapOptions { scale: 1.0, offset: 0.0, spacing: glam::DVec2::new(74.4, 92.6) };
    let f = load_heightmap(std::path::Path::new("tests/data/jacksboro-fault.png"), &o).unwrap();
    let args: Vec<u32> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let (w, h) = (args[0], args[1]);
    let cam = Camera { eye: DVec3::new(15000.0, 12000.0, 558.54), target: DVec3::new(15100.0, 12060.0, 586.6), up: DVec3::Z, fov_y_deg: 60.0, near: 0.1, far: 100000.0 };
    let s = TextureStreaming::for_image(w, h);
    println!("atlas {:?} quadtree {:?}", s.atlas, s.quadtree);
    let bounds = HeightBounds::new(&f, s.quadtree.max_depth).unwrap();
    let view = View { eye: cam.eye, pixel_footprint: View::pixel_footprint_for(60f64.to_radians(), h), frustum: Some(frustum_planes(cam.view_proj_f64(w as f64 / h as f64))) };
    let needed = select_tiles(f.extent(), &view, &s.quadtree, &|n| bounds.bounds(n)).unwrap();
    let mut by: BTreeMap<u32, usize> = BTreeMap::new();
    let mut lv: BTreeMap<u32, usize> = BTreeMap::new();
    for t in &needed { *by.entry(t.size).or_default() += 1; *lv.entry(t.node.level).or_default() += 1; }
    println!("needed {} by size {:?} by level {:?}", needed.len(), by, lv);
    for size in [16,32,64,128,256] { println!("capacity {size}: {}", s.atlas.slots_per_texture(size) * s.atlas.textures_of(size)); }
    let mut cache = TileCache::new(s.atlas).unwrap();
    for fr in 0..8 { let p = cache.plan_frame(fr, &needed, s.budget); println!("{fr}: {:?}", p.stats); }
}
