//! Point objects placed in a scene: sequential point trees (§10.1) drawn at
//! one or many places ("instances": one tree drawn at many places, e.g. the
//! procedural rocks of §6.1.4 scattered over the terrain).

use std::path::Path;
use std::sync::Arc;

use glam::{DMat4, DQuat, DVec3};

use super::build::estimate::complete_cloud;
use super::build::hybrid::{build_hybrid, HybridMesh};
use super::build::input::{load_points_file, PointInput};
use super::build::rocks::{generate_rock, rock_field};
use super::build::sampling::{sample_mesh, SamplingMethod, SamplingOptions};
use super::build::spt::{build_spt, SequentialPointTree, SptOptions};
use super::build::spt_file::read_spt;
use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::random::SplitMix64;
use crate::surface::bspline::sample_bspline;

/// A similarity transform: scale, then rotation, then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointTransform {
    pub translation: DVec3,
    pub rotation: DQuat,
    /// Uniform scale (> 0).
    pub scale: f64,
}

impl Default for PointTransform {
    fn default() -> Self {
        PointTransform {
            translation: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            scale: 1.0,
        }
    }
}

impl PointTransform {
    /// Object → world matrix.
    pub fn matrix(&self) -> DMat4 {
        DMat4::from_scale_rotation_translation(DVec3::splat(self.scale), self.rotation, self.translation)
    }

    /// Parses `t=X,Y,Z;r=RX,RY,RZ;s=S` (each part optional, any order):
    /// translation in world units, rotation in degrees about x, then y, then
    /// z (extrinsic), uniform scale.
    pub fn parse(text: &str) -> Result<PointTransform> {
        let bad = |msg: String| Error::invalid("points.transform", format!("'{text}': {msg}"));
        let mut out = PointTransform::default();
        for part in text.split(';').map(str::trim).filter(|p| !p.is_empty()) {
            let (key, value) = part
                .split_once('=')
                .ok_or_else(|| bad(format!("'{part}' is not key=value (keys t, r, s)")))?;
            let numbers = value
                .split(',')
                .map(|v| v.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
                .collect::<Option<Vec<f64>>>()
                .ok_or_else(|| bad(format!("'{value}' is not a list of finite numbers")))?;
            match (key.trim(), numbers.as_slice()) {
                ("t", &[x, y, z]) => out.translation = DVec3::new(x, y, z),
                ("r", &[x, y, z]) => {
                    out.rotation =
                        DQuat::from_euler(glam::EulerRot::ZYX, z.to_radians(), y.to_radians(), x.to_radians())
                }
                ("s", &[s]) if s > 0.0 => out.scale = s,
                ("s", &[s]) => return Err(bad(format!("scale {s} is not positive"))),
                ("t" | "r", _) => return Err(bad(format!("{key} needs three numbers"))),
                ("s", _) => return Err(bad("s needs one number".into())),
                (other, _) => return Err(bad(format!("unknown key '{other}' (keys t, r, s)"))),
            }
        }
        Ok(out)
    }
}

/// What a point object is, for the semantic class AOV (`crate::view::aov`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PointClass {
    /// A procedural rock (§6.1.4).
    Rock,
    /// Anything loaded from a file: scans, meshes.
    #[default]
    Scan,
    /// A procedural plant (chapter 10 introduction, Fig. 10.12).
    Vegetation,
}

impl PointClass {
    /// The class id of the ids AOV.
    pub fn id(self) -> u32 {
        match self {
            PointClass::Rock => crate::view::aov::CLASS_ROCK,
            PointClass::Scan => crate::view::aov::CLASS_SCAN,
            PointClass::Vegetation => crate::view::aov::CLASS_VEGETATION,
        }
    }
}

/// A point object: one sequential point tree, and for hybrid point–polygon
/// rendering (§10.1.8) the mesh's triangles.
#[derive(Clone, Debug)]
pub struct PointObject {
    /// For messages and statistics (file name, "rock 3").
    pub name: String,
    /// Its semantic class (scan unless made a rock).
    pub class: PointClass,
    /// The splat list (for a hybrid object, with the floors of `HybridMesh::point_tree`).
    pub tree: Arc<SequentialPointTree>,
    /// The triangles drawn where they are large in the image.
    pub hybrid: Option<Arc<HybridMesh>>,
    /// An open surface (leaves, blades): its back-facing splats and
    /// triangles are drawn whatever
    /// [`crate::points::render::SplatSettings::two_sided`] says.
    pub two_sided: bool,
    /// Thin its instances stochastically where they are smaller than a few
    /// pixels (`crate::points::render::selection`): for the many small
    /// copies of vegetation.
    pub thinning: bool,
}

impl PointObject {
    /// A points-only object.
    pub fn new(name: impl Into<String>, tree: SequentialPointTree) -> PointObject {
        PointObject {
            name: name.into(),
            class: PointClass::Scan,
            tree: Arc::new(tree),
            hybrid: None,
            two_sided: false,
            thinning: false,
        }
    }

    /// The same object for another threshold ε (unchanged when it already has it).
    pub fn with_epsilon(&self, epsilon: f32) -> Result<PointObject> {
        if self.tree.epsilon == epsilon {
            return Ok(self.clone());
        }
        Ok(match &self.hybrid {
            None => PointObject {
                tree: Arc::new(self.tree.with_epsilon(epsilon)?),
                ..self.clone()
            },
            Some(hybrid) => {
                let (tree, hybrid) = hybrid.with_epsilon(epsilon)?;
                PointObject {
                    tree: Arc::new(tree),
                    hybrid: Some(Arc::new(hybrid)),
                    ..self.clone()
                }
            }
        })
    }

    /// Triangles of a hybrid object (0 otherwise).
    pub fn triangle_count(&self) -> usize {
        self.hybrid.as_ref().map_or(0, |h| h.triangles.len())
    }
}

/// One placement of an object.
#[derive(Clone, Copy, Debug)]
pub struct PointInstance {
    /// Index into [`PointScene::objects`].
    pub object: usize,
    pub transform: PointTransform,
}

/// The point objects of a scene and where they are drawn.
#[derive(Clone, Debug, Default)]
pub struct PointScene {
    pub objects: Vec<PointObject>,
    pub instances: Vec<PointInstance>,
}

impl PointScene {
    /// Whether nothing is drawn.
    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    /// Adds `object`, drawn once with `transform`.
    pub fn add(&mut self, object: PointObject, transform: PointTransform) {
        self.objects.push(object);
        self.instances.push(PointInstance {
            object: self.objects.len() - 1,
            transform,
        });
    }

    /// Draws object `object` (an index into [`PointScene::objects`]) once
    /// more with `transform`; its splat list is shared, not copied.
    pub fn add_instance(&mut self, object: usize, transform: PointTransform) -> Result<()> {
        if object >= self.objects.len() {
            return Err(Error::invalid(
                "points instance",
                format!("object {object} does not exist ({} objects)", self.objects.len()),
            ));
        }
        self.instances.push(PointInstance { object, transform });
        Ok(())
    }

    /// Moves the objects and instances of `other` into this scene.
    pub fn append(&mut self, other: PointScene) {
        let offset = self.objects.len();
        self.objects.extend(other.objects);
        self.instances.extend(other.instances.into_iter().map(|mut i| {
            i.object += offset;
            i
        }));
    }

    /// Checks the instance indices and transforms.
    pub fn validate(&self) -> Result<()> {
        for (i, inst) in self.instances.iter().enumerate() {
            if inst.object >= self.objects.len() {
                return Err(Error::invalid(
                    format!("point instance {i}"),
                    format!("object {} of {}", inst.object, self.objects.len()),
                ));
            }
            let t = &inst.transform;
            if !(t.translation.is_finite() && t.rotation.is_finite() && t.scale.is_finite() && t.scale > 0.0) {
                return Err(Error::invalid(format!("point instance {i}"), "transform is not finite"));
            }
        }
        Ok(())
    }

    /// Total splats over all objects (each object's list stored once).
    pub fn total_splats(&self) -> usize {
        self.objects.iter().map(|o| o.tree.nodes.len()).sum()
    }
}

/// How mesh and point-cloud files become trees.
#[derive(Clone, Debug, PartialEq)]
pub struct PointLoadOptions {
    /// Surfels sampled from a mesh.
    pub mesh_samples: usize,
    pub sampling: SamplingMethod,
    pub seed: u64,
    pub spt: SptOptions,
    /// Keep a mesh's triangles for hybrid point–polygon rendering (§10.1.8);
    /// point clouds and SPT files have none and stay points only.
    pub hybrid: bool,
    /// With `hybrid`: every point of the object in this sRGB colour, so the
    /// points that replace small triangles stand out (Fig. 10.8's red);
    /// None: the surface's own colours. Set after the tree is built: the
    /// selection (§10.1.9's colour term included) stays as without it.
    pub hybrid_points_color: Option<[u8; 3]>,
}

impl Default for PointLoadOptions {
    fn default() -> Self {
        PointLoadOptions {
            mesh_samples: 50_000,
            sampling: SamplingMethod::Stratified,
            seed: 1,
            spt: SptOptions::default(),
            hybrid: false,
            hybrid_points_color: None,
        }
    }
}

/// Loads a PLY, OBJ or SPT file as a point object: meshes are sampled into
/// surfels, point clouds completed (normals, radii), both built into a tree;
/// SPT files are read as they are.
pub fn load_point_object(path: &Path, options: &PointLoadOptions) -> Result<PointObject> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    let is_spt = path
        .extension()
        .is_some_and(|e| e.to_string_lossy().eq_ignore_ascii_case("spt"));
    let in_file = |e: Error| Error::invalid(path.display().to_string(), e.to_string());
    if is_spt {
        return Ok(PointObject::new(name, read_spt(path)?));
    }
    let sampling = SamplingOptions {
        count: options.mesh_samples,
        method: options.sampling,
        seed: options.seed,
    };
    let surfels = match load_points_file(path)? {
        PointInput::Mesh(mesh) if options.hybrid => {
            let (mut tree, hybrid) = build_hybrid(&mesh, &sampling, &options.spt, &mut |_| {}).map_err(in_file)?;
            if let Some(color) = options.hybrid_points_color {
                tree.nodes.iter_mut().for_each(|n| n.color = color);
            }
            return Ok(PointObject {
                hybrid: Some(Arc::new(hybrid)),
                ..PointObject::new(name, tree)
            });
        }
        PointInput::Mesh(mesh) => sample_mesh(&mesh, &sampling),
        PointInput::Points(cloud) => complete_cloud(&cloud),
    }
    .map_err(in_file)?;
    let tree = build_spt(&surfels, &options.spt, &mut |_| {}).map_err(in_file)?;
    Ok(PointObject::new(name, tree))
}

/// Procedural rocks (§6.1.4) scattered over a height field as ground
/// detail: `shapes` distinct rocks, each sampled into `samples` surfels and
/// built into a tree once, drawn as `count` instances at random places with
/// random yaw and scale `scale_range`, sunk by a fifth of their height.
/// Deterministic per `seed`.
pub fn scatter_rocks(
    heights: &HeightField,
    shapes: usize,
    samples: usize,
    count: usize,
    scale_range: (f64, f64),
    seed: u64,
    spt: &SptOptions,
) -> Result<PointScene> {
    let mut scene = PointScene::default();
    if count == 0 {
        return Ok(scene);
    }
    for (i, params) in rock_field(shapes.max(1), seed).iter().enumerate() {
        let mesh = generate_rock(params)?;
        let surfels = sample_mesh(
            &mesh,
            &SamplingOptions {
                count: samples,
                method: SamplingMethod::Stratified,
                seed: seed ^ i as u64,
            },
        )?;
        let tree = build_spt(&surfels, spt, &mut |_| {})?;
        scene.objects.push(PointObject {
            class: PointClass::Rock,
            ..PointObject::new(format!("rock {i}"), tree)
        });
    }
    let extent = heights.extent();
    let mut rng = SplitMix64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    for _ in 0..count {
        let x = rng.next_f64() * extent.x;
        let y = rng.next_f64() * extent.y;
        let object = (rng.next_u64() % scene.objects.len() as u64) as usize;
        let scale = scale_range.0 * (scale_range.1 / scale_range.0).powf(rng.next_f64());
        let yaw = rng.next_f64() * std::f64::consts::TAU;
        let tree = &scene.objects[object].tree;
        let height = f64::from(tree.bounds_radius) * scale;
        let ground = sample_bspline(heights, x, y);
        scene.instances.push(PointInstance {
            object,
            transform: PointTransform {
                translation: DVec3::new(x, y, ground - 0.2 * height),
                rotation: DQuat::from_rotation_z(yaw),
                scale,
            },
        });
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_parse_and_reject_bad_input() {
        let t = PointTransform::parse("t=1,2,3; r=0,0,90; s=2").unwrap();
        assert_eq!(t.translation, DVec3::new(1.0, 2.0, 3.0));
        assert_eq!(t.scale, 2.0);
        let x = t.matrix().transform_point3(DVec3::X);
        assert!((x - DVec3::new(1.0, 4.0, 3.0)).length() < 1e-9, "{x}");
        assert_eq!(PointTransform::parse("").unwrap(), PointTransform::default());
        for bad in ["t=1,2", "s=0", "s=-1", "q=1", "t=1,x,3", "r", "s=inf"] {
            let e = PointTransform::parse(bad).unwrap_err().to_string();
            assert!(
                e.starts_with("invalid points.transform: ") && !e.contains('\n'),
                "{bad}: {e}"
            );
        }
    }
}
