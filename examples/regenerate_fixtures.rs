//! Regenerates the small fixtures in `tests/data/` (the committed
//! files are what the tests read): `cargo run --example regenerate_fixtures`.

use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn write_grey16(path: &Path, width: u32, height: u32, values: &[u16]) {
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(width, height, values.to_vec())
        .unwrap()
        .save(path)
        .unwrap();
}

fn main() {
    let dem = std::fs::read(data("jacksboro-fault.png")).unwrap();
    std::fs::write(data("truncated.png"), &dem[..1000]).unwrap();
    std::fs::write(data("empty.png"), b"").unwrap();
    std::fs::write(
        data("not-an-image.png"),
        b"This is a text file with a .png name, not an image.\n",
    )
    .unwrap();
    let colour = image::RgbImage::from_fn(4, 3, |x, y| image::Rgb([x as u8 * 60, y as u8 * 80, 128]));
    colour.save(data("colour.png")).unwrap();
    let ramp: Vec<u16> = (0..6u16)
        .flat_map(|r| (0..8u16).map(move |c| 1000 * r + 10 * c))
        .collect();
    write_grey16(&data("tiny-ramp.png"), 8, 6, &ramp);
    // Rainfall input map: 0 on the western edge to 255 on the eastern one.
    let rainfall = image::GrayImage::from_fn(33, 33, |x, _| image::Luma([(255.0 * x as f32 / 32.0).round() as u8]));
    rainfall.save(data("rainfall.png")).unwrap();

    use exr::prelude::*;
    let mut y: Vec<f32> = (0..12).map(|i| 100.0 + i as f32).collect();
    y[4 + 2] = f32::NAN; // column 2, row 1 of a 4×3 image
    let mut list = SmallVec::new();
    list.push(AnyChannel::new("Y", FlatSamples::F32(y)));
    let channels = AnyChannels::sort(list);
    let layer = Layer::new((4, 3), LayerAttributes::default(), Encoding::UNCOMPRESSED, channels);
    Image::from_layer(layer).write().to_file(data("nan.exr")).unwrap();
}
