//! Tests of the quadtree's tile selection (`quadtree.rs`).

use std::collections::HashSet;

use super::*;

const EXTENT: DVec2 = DVec2::new(8000.0, 4000.0);

fn flat(_: NodeId) -> NodeBounds {
    NodeBounds {
        z_min: 0.0,
        z_max: 100.0,
        geometric_error: 0.0,
    }
}

fn view(eye: DVec3) -> Footprint {
    Footprint {
        eye,
        pixel_footprint: Footprint::pixel_footprint_for(1.0, 1080),
        frustum: None,
    }
}

fn select(eye: DVec3) -> Vec<NeededTile> {
    select_tiles(EXTENT, &view(eye), &QuadtreeSettings::default(), &flat).unwrap()
}

#[test]
fn leaves_partition_the_rectangle() {
    let n = 1u32 << 10;
    for eye in [
        DVec3::new(100.0, 200.0, 50.0),
        DVec3::new(7999.0, 3999.0, 10.0),
        DVec3::new(4000.0, 2000.0, 3e3),
    ] {
        let tiles = select(eye);
        let mut cover = vec![0u8; (n * n) as usize];
        for t in &tiles {
            let k = n >> t.node.level;
            for y in t.node.y * k..(t.node.y + 1) * k {
                for x in t.node.x * k..(t.node.x + 1) * k {
                    cover[(y * n + x) as usize] += 1;
                }
            }
        }
        assert!(cover.iter().all(|&c| c == 1), "eye {eye}: {} tiles", tiles.len());
        assert!(tiles.windows(2).all(|w| selection_order(&w[0], &w[1]).is_lt()));
    }
}

#[test]
fn nearer_nodes_are_finer_and_sizes_in_bounds() {
    let s = QuadtreeSettings::default();
    let tiles = select(DVec3::new(100.0, 100.0, 20.0));
    let near = tiles.iter().min_by(|a, b| a.distance.total_cmp(&b.distance)).unwrap();
    let far = tiles.iter().max_by(|a, b| a.distance.total_cmp(&b.distance)).unwrap();
    assert!(near.node.level > far.node.level);
    assert!(near.node.rect(EXTENT).0.x < 1000.0 && near.node.level == s.max_depth);
    for t in &tiles {
        assert!(t.size.is_power_of_two() && (s.min_tile..=s.max_tile).contains(&t.size));
        assert!(t.node.level == s.max_depth || t.size <= 256, "{t:?}");
    }
    // Texels per metre fall off with distance.
    let density = |t: &NeededTile| f64::from(t.size - 2 * s.border) / (EXTENT.x / f64::from(1u32 << t.node.level));
    assert!(density(near) > density(far));
}

#[test]
fn far_eye_gives_the_root_only() {
    let tiles = select(DVec3::new(4000.0, 2000.0, 1e7));
    assert_eq!(tiles.len(), 1);
    assert_eq!((tiles[0].node, tiles[0].size), (NodeId::ROOT, 16));
}

#[test]
fn geometric_error_forces_splits() {
    let rough = |n: NodeId| NodeBounds {
        z_min: 0.0,
        z_max: 100.0,
        geometric_error: 500.0 / (1u32 << n.level) as f32,
    };
    let settings = QuadtreeSettings::default();
    let v = view(DVec3::new(4000.0, 2000.0, 1e5));
    assert_eq!(select_tiles(EXTENT, &v, &settings, &flat).unwrap().len(), 1);
    let tiles = select_tiles(EXTENT, &v, &settings, &rough).unwrap();
    assert_eq!(tiles.len(), 64, "splits to level 3 where the error is 0.6 px");
}

#[test]
fn frustum_drops_nodes_behind_the_camera() {
    let eye = DVec3::new(4000.0, 2000.0, 50.0);
    // Looking east: keep x ≥ eye.x (plus five planes that keep everything).
    let keep = DVec4::new(0.0, 0.0, 0.0, 1.0);
    let mut v = view(eye);
    v.frustum = Some([DVec4::new(1.0, 0.0, 0.0, -eye.x), keep, keep, keep, keep, keep]);
    let all = select(eye);
    let culled = select_tiles(EXTENT, &v, &QuadtreeSettings::default(), &flat).unwrap();
    assert!(!culled.is_empty() && culled.len() < all.len());
    assert!(culled.iter().all(|t| t.node.rect(EXTENT).1.x >= eye.x));
}

/// Texel density (texels per metre) of the leaf over each cell of the
/// finest grid (`max_depth` 10), None where no leaf is; panics where
/// leaves overlap.
fn density_map(tiles: &[NeededTile]) -> Vec<Option<f64>> {
    const GRID: u32 = 10;
    let n = 1u32 << GRID;
    let mut cover = vec![None; (n * n) as usize];
    for t in tiles {
        let k = n >> t.node.level;
        let density = f64::from(t.size - 8) / (EXTENT.x / f64::from(1u32 << t.node.level));
        for y in t.node.y * k..(t.node.y + 1) * k {
            for x in t.node.x * k..(t.node.x + 1) * k {
                let cell = &mut cover[(y * n + x) as usize];
                assert!(cell.is_none(), "{t:?} overlaps another leaf");
                *cell = Some(density);
            }
        }
    }
    cover
}

#[test]
fn views_looking_apart_get_the_union_finest_first() {
    let eye = DVec3::new(4000.0, 2000.0, 50.0);
    let keep = DVec4::new(0.0, 0.0, 0.0, 1.0);
    let facing = |sign: f64| Footprint {
        frustum: Some([DVec4::new(sign, 0.0, 0.0, -sign * eye.x), keep, keep, keep, keep, keep]),
        ..view(eye)
    };
    // East looks from the eye, west from 500 m west of it: different needs.
    let (east, west) = (
        facing(1.0),
        Footprint {
            eye: eye - DVec3::new(500.0, 0.0, 0.0),
            ..facing(-1.0)
        },
    );
    let s = QuadtreeSettings::default();
    let one = |v: &Footprint| select_tiles(EXTENT, v, &s, &flat).unwrap();
    let (a, b) = (density_map(&one(&east)), density_map(&one(&west)));
    let both = select_tiles_for_views(EXTENT, &[east, west], &s, &flat).unwrap();
    let union = density_map(&both);
    let keys: HashSet<NodeId> = both.iter().map(|t| t.node).collect();
    assert_eq!(keys.len(), both.len(), "a node selected twice");
    let (mut only_a, mut only_b) = (0, 0);
    for ((u, a), b) in union.iter().zip(&a).zip(&b) {
        assert_eq!(u.is_some(), a.is_some() || b.is_some(), "cover is not the union");
        only_a += usize::from(a.is_some() && b.is_none());
        only_b += usize::from(b.is_some() && a.is_none());
    }
    assert!(
        only_a > 0 && only_b > 0,
        "the views must each see something the other does not"
    );
    // Every leaf has the texels each view that sees it needs (rule 2),
    // unless clamped to the largest size.
    for t in &both {
        let (lo, hi) = t.node.rect(EXTENT);
        let (min, max) = (lo.extend(0.0), hi.extend(100.0));
        for v in [&east, &west] {
            if v.frustum.unwrap().iter().any(|p| box_outside(p, min, max)) {
                continue;
            }
            let distance = v.eye.clamp(min, max).distance(v.eye).max(MIN_DISTANCE);
            let needed = (hi - lo).max_element() / (v.pixel_footprint * distance);
            let inner = f64::from(t.size - 2 * s.border);
            assert!(inner >= needed || t.size == s.max_tile, "{t:?}: {needed} texels needed");
        }
    }
    assert!(both.len() > one(&east).len().max(one(&west).len()));
}

#[test]
fn overlapping_views_do_not_duplicate_tiles() {
    let s = QuadtreeSettings::default();
    let v = view(DVec3::new(1000.0, 1000.0, 300.0));
    let single = select_tiles(EXTENT, &v, &s, &flat).unwrap();
    let twice = select_tiles_for_views(EXTENT, &[v, v], &s, &flat).unwrap();
    assert_eq!(single, twice);
    // A view a little to the side shares most of the tiles.
    let near = Footprint {
        eye: v.eye + DVec3::new(50.0, 0.0, 0.0),
        ..v
    };
    let pair = select_tiles_for_views(EXTENT, &[v, near], &s, &flat).unwrap();
    density_map(&pair);
    assert!(pair.len() < single.len() * 3 / 2, "{} vs {}", pair.len(), single.len());
    assert!(select_tiles_for_views(EXTENT, &[], &s, &flat).is_err());
}

/// A view that would need every node at the deepest level (16.7 M
/// leaves) gets at most MAX_SELECTED, still a partition, finest near
/// the eye.
#[test]
fn selection_is_bounded() {
    let settings = QuadtreeSettings {
        max_depth: 12,
        ..QuadtreeSettings::default()
    };
    let v = Footprint {
        pixel_footprint: 1e-9,
        ..view(DVec3::new(10.0, 10.0, 50.0))
    };
    let tiles = select_tiles(EXTENT, &v, &settings, &flat).unwrap();
    assert!(
        tiles.len() <= MAX_SELECTED && tiles.len() > MAX_SELECTED / 2,
        "{}",
        tiles.len()
    );
    let area: f64 = tiles.iter().map(|t| 4f64.powi(-(t.node.level as i32))).sum();
    assert!((area - 1.0).abs() < 1e-9, "leaves cover {area}");
    let keys: HashSet<NodeId> = tiles.iter().map(|t| t.node).collect();
    for t in &tiles {
        let mut up = t.node.parent();
        while let Some(p) = up {
            assert!(!keys.contains(&p), "{t:?} overlaps {p:?}");
            up = p.parent();
        }
    }
    let nearest = tiles.iter().min_by(|a, b| a.distance.total_cmp(&b.distance)).unwrap();
    let coarsest = tiles.iter().map(|t| t.node.level).min().unwrap();
    assert!(
        nearest.node.level > coarsest + 2,
        "{nearest:?}, coarsest level {coarsest}"
    );
}

#[test]
fn invalid_settings_and_inputs_are_errors() {
    let d = QuadtreeSettings::default();
    let bad = [
        QuadtreeSettings { min_tile: 24, ..d },
        QuadtreeSettings { min_tile: 1024, ..d },
        QuadtreeSettings { border: 8, ..d },
        QuadtreeSettings { max_depth: 16, ..d },
        QuadtreeSettings { aim_texels: 4, ..d },
        QuadtreeSettings {
            pixel_error: f32::NAN,
            ..d
        },
    ];
    for s in bad {
        assert!(s.validate().is_err(), "{s:?}");
        assert!(select_tiles(EXTENT, &view(DVec3::ZERO), &s, &flat).is_err());
    }
    let v = Footprint {
        pixel_footprint: 0.0,
        ..view(DVec3::ZERO)
    };
    assert!(select_tiles(EXTENT, &v, &d, &flat).is_err());
    assert!(select_tiles(DVec2::new(0.0, 1.0), &view(DVec3::ZERO), &d, &flat).is_err());
    let nan = |_: NodeId| NodeBounds {
        z_min: f32::NAN,
        z_max: 0.0,
        geometric_error: 0.0,
    };
    assert!(select_tiles(EXTENT, &view(DVec3::ZERO), &d, &nan).is_err());
}

#[test]
fn node_ids_relate() {
    let n = NodeId { level: 3, x: 5, y: 2 };
    assert_eq!(n.parent(), Some(NodeId { level: 2, x: 2, y: 1 }));
    assert_eq!(NodeId::ROOT.parent(), None);
    assert!(n.children().iter().all(|c| c.parent() == Some(n) && n.contains(c)));
    assert!(NodeId::ROOT.contains(&n) && n.contains(&n) && !n.contains(&NodeId::ROOT));
    assert!(!NodeId { level: 2, x: 1, y: 1 }.contains(&n));
    assert_eq!(n.rect(EXTENT), (DVec2::new(5000.0, 1000.0), DVec2::new(6000.0, 1500.0)));
}
