//! Writes the binary seed files of the fuzz corpus (`tests/data/fuzz/`):
//! `cargo run --example fuzz_corpus`. The text seeds are written by hand;
//! see `tests/data/fuzz/README.md`.

use std::path::{Path, PathBuf};

use alpenglow::bench::{ClipLine, ClipLines, Surfel};
use alpenglow::files::write_spt;
use alpenglow::tools::spt::{build_spt, SptOptions};
use glam::Vec3;

fn corpus(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz").join(path)
}

fn main() {
    // Height maps: a 5×4 16-bit ramp, a 3×3 8-bit one.
    let ramp: Vec<u16> = (0..20u16).map(|i| 700 * (i / 5) + 37 * (i % 5)).collect();
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(5, 4, ramp)
        .unwrap()
        .save(corpus("png/ramp16.png"))
        .unwrap();
    image::GrayImage::from_fn(3, 3, |x, y| image::Luma([(x * 80 + y * 10) as u8]))
        .save(corpus("png/grey8.png"))
        .unwrap();
    // Input map: a 9×9 8-bit gradient (loaded by the same loader).
    image::GrayImage::from_fn(9, 9, |x, _| image::Luma([(x * 31) as u8]))
        .save(corpus("input_map/rainfall9.png"))
        .unwrap();

    // EXR: 4×3 float `Y`, uncompressed and ZIP; 3×2 half `R`.
    use exr::prelude::*;
    let y: Vec<f32> = (0..12).map(|i| 100.0 + 2.5 * i as f32).collect();
    for (name, encoding) in [
        ("y-raw.exr", Encoding::UNCOMPRESSED),
        ("y-zip.exr", Encoding::SMALL_LOSSLESS),
    ] {
        let mut list = SmallVec::new();
        list.push(AnyChannel::new("Y", FlatSamples::F32(y.clone())));
        let layer = Layer::new((4, 3), LayerAttributes::default(), encoding, AnyChannels::sort(list));
        Image::from_layer(layer)
            .write()
            .to_file(corpus(&format!("exr/{name}")))
            .unwrap();
    }
    let r: Vec<f16> = (0..6).map(|i| f16::from_f32(i as f32 * 0.5)).collect();
    let mut list = SmallVec::new();
    list.push(AnyChannel::new("R", FlatSamples::F16(r)));
    let layer = Layer::new(
        (3, 2),
        LayerAttributes::default(),
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(list),
    );
    Image::from_layer(layer)
        .write()
        .to_file(corpus("exr/r-half.exr"))
        .unwrap();

    // Binary PLY: a quad of float positions, uchar colours, int indices.
    for (name, format, little) in [
        ("ply/quad-le.ply", "binary_little_endian", true),
        ("ply/points-be.ply", "binary_big_endian", false),
    ] {
        let mesh = little;
        let mut bytes = format!(
            "ply\nformat {format} 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n{}end_header\n",
            if mesh {
                "element face 1\nproperty list uchar int vertex_indices\n"
            } else {
                ""
            }
        )
        .into_bytes();
        let f = |v: f32| if little { v.to_le_bytes() } else { v.to_be_bytes() };
        for (i, p) in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]]
            .iter()
            .enumerate()
        {
            for v in p {
                bytes.extend_from_slice(&f(*v));
            }
            bytes.extend_from_slice(&[40 * i as u8, 200, 30]);
        }
        if mesh {
            bytes.push(4);
            for i in 0..4i32 {
                bytes.extend_from_slice(&i.to_le_bytes());
            }
        }
        std::fs::write(corpus(name), bytes).unwrap();
    }

    // SPT: a tree over a 4×3 grid of surfels, some with clip lines.
    let mut surfels = Vec::new();
    for i in 0..4 {
        for j in 0..3 {
            let (x, y) = (i as f32 * 0.5, j as f32 * 0.5);
            surfels.push(Surfel {
                position: Vec3::new(x, y, 0.1 * x * y),
                normal: Vec3::new(0.1, -0.05, 1.0).normalize(),
                radius: 0.3,
                color: [(i * 60) as u8, (j * 80) as u8, 90],
                clip: if (i + j) % 3 == 0 {
                    ClipLines([
                        Some(ClipLine {
                            angle: 0.7,
                            offset: 0.05,
                        }),
                        None,
                    ])
                } else {
                    ClipLines::NONE
                },
            });
        }
    }
    let tree = build_spt(&surfels, &SptOptions::default(), &mut |_| {}).unwrap();
    write_spt(&corpus("spt/grid.spt"), &tree).unwrap();
    geotiff_seeds();
}

/// GeoTIFF: a 4×3 16-bit field in degrees (pixel scale and tie point,
/// geographic model) and a 3×3 float field with a model transformation in
/// metres and a no-data value not present in the data.
fn geotiff_seeds() {
    use tiff::encoder::colortype::{Gray16, Gray32Float};
    use tiff::encoder::TiffEncoder;
    use tiff::tags::Tag;
    std::fs::create_dir_all(corpus("geotiff")).unwrap();
    let file = std::fs::File::create(corpus("geotiff/degrees16.tif")).unwrap();
    let mut tiff = TiffEncoder::new(file).unwrap();
    let mut image = tiff.new_image::<Gray16>(4, 3).unwrap();
    let e = image.encoder();
    e.write_tag(Tag::ModelPixelScaleTag, &[1.0 / 1200.0, 1.0 / 1200.0, 0.0][..])
        .unwrap();
    e.write_tag(Tag::ModelTiepointTag, &[0.0, 0.0, 0.0, 7.0, 45.5, 0.0][..])
        .unwrap();
    e.write_tag(Tag::GeoKeyDirectoryTag, &[1u16, 1, 0, 1, 1024, 0, 1, 2][..])
        .unwrap();
    let values: Vec<u16> = (0..12u16).map(|i| 300 + 17 * i).collect();
    image.write_data(&values).unwrap();
    let file = std::fs::File::create(corpus("geotiff/metres-float.tif")).unwrap();
    let mut tiff = TiffEncoder::new(file).unwrap();
    let mut image = tiff.new_image::<Gray32Float>(3, 3).unwrap();
    let e = image.encoder();
    let transform = [
        30.0,
        0.0,
        0.0,
        500_000.0,
        0.0,
        -30.0,
        0.0,
        4_100_000.0,
        0.0,
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
    ];
    e.write_tag(Tag::ModelTransformationTag, &transform[..]).unwrap();
    e.write_tag(Tag::GeoKeyDirectoryTag, &[1u16, 1, 0, 1, 1024, 0, 1, 1][..])
        .unwrap();
    e.write_tag(Tag::GdalNodata, "-9999").unwrap();
    let floats: Vec<f32> = (0..9).map(|i| 12.5 * i as f32 - 3.0).collect();
    image.write_data(&floats).unwrap();
}
