//! Surface layers from a real image (dissertation §8.3; `ALGORITHMS.md` §5):
//! a true-colour satellite or aerial image registered to the height field
//! is classified into surface types, and for each type the conditions
//! under which it appears (altitude, slope, the extra input maps) are
//! estimated as sampled functions; a layer tree with one layer per type
//! then reproduces the image's surface from the height field alone.
//!
//! The steps, in the text's order (each module documents its decisions):
//!
//! 1. [`shading`]: the image's baked-in light, modelled from the height
//!    field for the image's sun (self and cast shadow) — §8.3 leaves
//!    shading to the colour space; here it is modelled so that shadowed
//!    walls are neither rock nor water;
//! 2. [`classify`]: HSV + RGB per pixel, near-grey pixels into reserved
//!    classes, dark pixels in modelled shadow set aside;
//! 3. [`kmeans`]: the chromatic pixels clustered in the hue–saturation
//!    histogram (k fixed or chosen by the silhouette);
//! 4. [`distributions`]: per class and input quantity the histogram where
//!    the class occurs, scaled to mean 0.5 and clamped (snow below a
//!    minimum altitude is cloud and not counted);
//! 5. [`tree`]: root = the most common class, one level-1 child per other
//!    class with its mean colour (linear albedo), written as TOML;
//! 6. optionally [`level2`]: the larger level-1 classes split by a second
//!    clustering inside each, the sub-classes their level-2 children.
//!
//! A mask (`FromImageOptions::exclude`, `--mask`) leaves pixels out of
//! everything: the text excludes the land cultivated by humans from the
//! distribution functions (§8.3.2).
//!
//! # Registration
//! The image covers the height field's area pixel for pixel: its size is
//! the field's `columns × rows` times an integer factor `s` (1, 2, …), and
//! image pixel `(i, j)` lies inside field cell `(i / s, j / s)` (pixels are
//! areas whose outer edges coincide with those of the field's cells, as in
//! a GeoTIFF with `AREA_OR_POINT=Area`). Its centre is at field column
//! `(i + ½)/s − ½` and image row `(j + ½)/s − ½`, clamped onto the field;
//! image rows run north to south ([`RowOrder::NorthUp`], the usual raster
//! order) or south to north like the field's rows.

pub mod calibrate;
pub mod classify;
pub mod distributions;
pub mod kmeans;
pub mod level2;
pub mod plot;
pub mod shading;
pub mod tree;

use glam::DVec2;
use image::RgbImage;

use crate::error::{Error, Result};
use crate::io::heightmap::{HeightField, RowOrder};

pub use classify::PixelStatus;
pub use tree::GeneratedLayers;

/// Most classes k-means may find (`--classes`).
pub const MAX_CLASSES: usize = 8;
/// Classes tried by the automatic choice.
pub const AUTO_CLASSES: std::ops::RangeInclusive<usize> = 2..=6;

/// How many chromatic classes k-means finds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ClassCount {
    /// Exactly k (1..=[`MAX_CLASSES`]).
    Fixed(usize),
    /// The k of `AUTO_CLASSES` with the largest silhouette (`kmeans`).
    Auto,
}

/// Options of [`build_layers`].
#[derive(Clone, Debug, PartialEq)]
pub struct FromImageOptions {
    /// Chromatic classes (the reserved grey classes come on top).
    pub classes: ClassCount,
    /// Where the image's row 0 lies.
    pub image_rows: RowOrder,
    /// The image's sun: azimuth clockwise from north and elevation, degrees.
    pub sun_azimuth_deg: f64,
    pub sun_elevation_deg: f64,
    /// Whether dark pixels in modelled shadow are set aside ([`classify`]);
    /// off only to show what they would become.
    pub shade_handling: bool,
    /// Snow below this altitude (metres) is cloud; `None`: 60 % of the way
    /// from the field's lowest to its highest sample.
    pub snow_min_altitude: Option<f32>,
    /// Samples of each distribution function (1..=64).
    pub bins: usize,
    /// Seed of k-means' initialisation.
    pub seed: u64,
    /// Whether the layers' noise bias is calibrated to the class fractions
    /// ([`calibrate`]).
    pub calibrate: bool,
    /// Weight of the shade-normalised value in the clustering space
    /// (`kmeans`); 0: hue and saturation alone.
    pub value_weight: f64,
    /// Sub-classes per larger level-1 class ([`level2`], 2..=[`level2::MAX_SUBCLASSES`]);
    /// `None`: no level 2.
    pub level2: Option<usize>,
    /// Pixels left out of the estimation (`true`), one per image pixel
    /// row-major from image row 0 ([`load_mask`]); `None`: none.
    pub exclude: Option<Vec<bool>>,
}

impl Default for FromImageOptions {
    fn default() -> Self {
        FromImageOptions {
            classes: ClassCount::Auto,
            image_rows: RowOrder::NorthUp,
            sun_azimuth_deg: 150.0,
            sun_elevation_deg: 30.0,
            shade_handling: true,
            snow_min_altitude: None,
            bins: 48,
            seed: 1,
            calibrate: true,
            value_weight: 0.5,
            level2: None,
            exclude: None,
        }
    }
}

impl FromImageOptions {
    fn validate(&self) -> Result<()> {
        if let ClassCount::Fixed(k) = self.classes {
            if !(1..=MAX_CLASSES).contains(&k) {
                return Err(Error::invalid(
                    "from_image.classes",
                    format!("{k} is out of range 1..={MAX_CLASSES}"),
                ));
            }
        }
        if !(self.sun_azimuth_deg.is_finite() && (-360.0..=360.0).contains(&self.sun_azimuth_deg)) {
            return Err(Error::invalid(
                "from_image.sun_azimuth_deg",
                "must be within ±360 degrees",
            ));
        }
        if !(self.sun_elevation_deg > 0.0 && self.sun_elevation_deg <= 90.0) {
            return Err(Error::invalid(
                "from_image.sun_elevation_deg",
                "must be in (0, 90] degrees",
            ));
        }
        if !(0.0..=4.0).contains(&self.value_weight) {
            return Err(Error::invalid(
                "from_image.value_weight",
                format!("{} is out of range 0..=4", self.value_weight),
            ));
        }
        if let Some(k) = self.level2 {
            if !(2..=level2::MAX_SUBCLASSES).contains(&k) {
                return Err(Error::invalid(
                    "from_image.level2",
                    format!("{k} is out of range 2..={}", level2::MAX_SUBCLASSES),
                ));
            }
        }
        if self.snow_min_altitude.is_some_and(|a| !a.is_finite()) {
            return Err(Error::invalid("from_image.snow_min_altitude", "must be finite"));
        }
        if !(1..=crate::surface::layers::MAX_SAMPLES).contains(&self.bins) {
            return Err(Error::invalid(
                "from_image.bins",
                format!(
                    "{} is out of range 1..={}",
                    self.bins,
                    crate::surface::layers::MAX_SAMPLES
                ),
            ));
        }
        Ok(())
    }
}

/// Where the image's pixels lie on the height field (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Registration {
    pub width: u32,
    pub height: u32,
    /// Image pixels per field cell along each axis.
    pub factor: u32,
    columns: u32,
    rows: u32,
    spacing: DVec2,
    north_up: bool,
}

impl Registration {
    /// The registration of a `width × height` image on `field`; an error
    /// unless the image is an integer multiple of the field's grid.
    pub fn new(width: u32, height: u32, field: &HeightField, rows: RowOrder) -> Result<Registration> {
        let (c, r) = (field.columns, field.rows);
        let factor = width.checked_div(c).unwrap_or(0);
        if c < 2 || r < 2 || factor == 0 || width != factor * c || height != factor * r {
            return Err(Error::invalid(
                "from_image.image",
                format!("{width}×{height} pixels is not an integer multiple of the height field's {c}×{r} grid"),
            ));
        }
        Ok(Registration {
            width,
            height,
            factor,
            columns: c,
            rows: r,
            spacing: field.spacing,
            north_up: rows == RowOrder::NorthUp,
        })
    }

    /// World xy (metres) of the centre of pixel `(i, j)`.
    pub fn world(&self, i: u32, j: u32) -> DVec2 {
        let s = f64::from(self.factor);
        let last = DVec2::new(f64::from(self.columns - 1), f64::from(self.rows - 1));
        let u = ((f64::from(i) + 0.5) / s - 0.5).clamp(0.0, last.x);
        let v = ((f64::from(j) + 0.5) / s - 0.5).clamp(0.0, last.y);
        let row = if self.north_up { last.y - v } else { v };
        DVec2::new(u, row) * self.spacing
    }

    /// Pixels of the image.
    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// World xy of every pixel, row-major from image row 0.
    pub fn world_positions(&self) -> Vec<DVec2> {
        (0..self.height)
            .flat_map(|j| (0..self.width).map(move |i| (i, j)))
            .map(|(i, j)| self.world(i, j))
            .collect()
    }
}

/// Reads a colour image (PNG or JPEG, 8-bit; grey is taken as RGB, alpha
/// dropped) within `limits`: the declared size is checked before decoding.
pub fn load_rgb_image(path: &std::path::Path, limits: &crate::io::limits::InputLimits) -> Result<RgbImage> {
    let bytes = crate::io::read_input_limited(path, limits.max_file_bytes)?;
    let reader = image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| Error::input(path, e))?;
    if reader.format().is_none() {
        return Err(Error::input(path, "not a PNG or JPEG image"));
    }
    let (w, h) = reader.into_dimensions().map_err(|e| Error::input(path, e))?;
    limits
        .check_image(u64::from(w), u64::from(h), 4)
        .map_err(|m| Error::input(path, m))?;
    let image = image::load_from_memory(&bytes).map_err(|e| Error::input(path, e.to_string().replace('\n', " ")))?;
    Ok(image.to_rgb8())
}

/// Reads a mask of pixels to leave out (PNG or JPEG, any colour type): a
/// pixel is excluded where any colour channel is non-zero. Errors (one
/// line, naming `path`): not an image, a size other than `width × height`
/// (the colour image's), every pixel excluded.
pub fn load_mask(
    path: &std::path::Path,
    width: u32,
    height: u32,
    limits: &crate::io::limits::InputLimits,
) -> Result<Vec<bool>> {
    let mask = load_rgb_image(path, limits)?;
    if mask.dimensions() != (width, height) {
        return Err(Error::input(
            path,
            format!(
                "the mask is {}×{} pixels, the image {width}×{height}",
                mask.width(),
                mask.height()
            ),
        ));
    }
    let exclude: Vec<bool> = mask.pixels().map(|p| p.0 != [0; 3]).collect();
    if exclude.iter().all(|&e| e) {
        return Err(Error::input(path, "the mask excludes every pixel"));
    }
    Ok(exclude)
}

/// Checks `options.exclude` against `registration`.
fn check_exclude(options: &FromImageOptions, registration: &Registration) -> Result<()> {
    let Some(exclude) = &options.exclude else {
        return Ok(());
    };
    if exclude.len() != registration.pixels() {
        return Err(Error::invalid(
            "from_image.mask",
            format!(
                "{} mask pixels for a {}×{} image",
                exclude.len(),
                registration.width,
                registration.height
            ),
        ));
    }
    if exclude.iter().all(|&e| e) {
        return Err(Error::invalid("from_image.mask", "the mask excludes every pixel"));
    }
    Ok(())
}

/// Surface layers estimated from `image` over `field` (module docs): the
/// layer tree as TOML with the classification behind it. `maps` are the
/// extra input maps ([`crate::surface::layers::INPUT_NAMES`] order),
/// each spanning the field corner to corner; every present map becomes a
/// constraint of every child layer.
pub fn build_layers(
    image: &RgbImage,
    field: &HeightField,
    maps: &[Option<HeightField>; 3],
    options: &FromImageOptions,
) -> Result<GeneratedLayers> {
    options.validate()?;
    field.validate(std::path::Path::new("height field"))?;
    let registration = Registration::new(image.width(), image.height(), field, options.image_rows)?;
    check_exclude(options, &registration)?;
    let positions = registration.world_positions();
    let samples = distributions::Samples::at(field, maps, &positions)?;
    let light = shading::relative_illumination(field, &positions, options.sun_azimuth_deg, options.sun_elevation_deg);
    let (lo, hi) = field.min_max();
    let snow_min = options.snow_min_altitude.unwrap_or(lo + 0.6 * (hi - lo));
    let mut classification = classify::classify(image, &registration, &light, &samples.altitude, snow_min, options)?;
    if let Some(k) = options.level2 {
        level2::refine(
            &mut classification,
            image,
            &light,
            k,
            options.value_weight,
            options.seed,
        );
    }
    let functions = distributions::estimate(&classification, &samples, options.bins);
    let provenance = tree::Provenance {
        options: options.clone(),
        snow_min_altitude: snow_min,
        spacing: field.spacing,
    };
    let mut generated = tree::build(&classification, &functions, &provenance);
    if options.calibrate {
        let fractions = classification.fractions();
        let own: Vec<f64> = generated.layers.iter().map(|l| fractions[l.class]).collect();
        let targets = calibrate::with_children(&generated.layers, own);
        let points = calibrate::sample_positions(&positions, registration.width as usize, &classification.status);
        generated.predicted =
            calibrate::calibrate(&mut generated.layers, &targets, tree::layer_tree, field, maps, &points)?;
        let shares: Vec<String> = (generated.layers.iter())
            .zip(&generated.predicted)
            .map(|(l, f)| format!("{} {:.1} %", l.name, 100.0 * f))
            .collect();
        generated.header.push(format!(
            "Noise bias calibrated to the class areas; predicted dominant-layer areas (a level-1 layer's with its \
             level-2 children's): {}.",
            shares.join(", ")
        ));
    }
    Ok(generated)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;

    #[test]
    fn pixels_register_area_to_area() {
        let field = HeightField::from_fn(2, 2, DVec2::splat(10.0), |_, _| 0.0);
        let north = Registration::new(4, 4, &field, RowOrder::NorthUp).unwrap();
        assert_eq!(north.factor, 2);
        // Outer half-pixels clamp onto the field's edge samples.
        assert_eq!(north.world(0, 0), DVec2::new(0.0, 10.0));
        assert_eq!(north.world(3, 3), DVec2::new(10.0, 0.0));
        // Pixel centres a quarter cell inside: column 0.25, image row 0.75.
        assert_eq!(north.world(1, 2), DVec2::new(2.5, 2.5));
        let south = Registration::new(4, 4, &field, RowOrder::SouthUp).unwrap();
        assert_eq!(south.world(1, 2), DVec2::new(2.5, 7.5));
        assert!(Registration::new(5, 4, &field, RowOrder::NorthUp).is_err());
        assert!(Registration::new(4, 6, &field, RowOrder::NorthUp).is_err());
    }

    /// A given input map becomes a sampled constraint of every child over
    /// the map's range, high where the class lies.
    #[test]
    fn input_maps_become_constraints() {
        let field = HeightField::from_fn(16, 12, DVec2::splat(100.0), |_, _| 500.0);
        // Rainfall rising to the north on its own 2×2 grid (corner to corner).
        let rain = HeightField::from_fn(2, 2, DVec2::ONE, |_, r| 100.0 * r as f32);
        let image = RgbImage::from_fn(16, 12, |_, j| {
            image::Rgb(if j < 4 { [170, 150, 120] } else { [60, 80, 40] })
        });
        let options = FromImageOptions {
            classes: ClassCount::Fixed(2),
            calibrate: false,
            ..Default::default()
        };
        let generated = build_layers(&image, &field, &[Some(rain), None, None], &options).unwrap();
        let tree = generated.tree().unwrap();
        assert!(tree.uses_input(0) && !tree.uses_input(1));
        let Some(crate::surface::layers::Constraint::Sampled(f)) = &tree.layers[1].layer.inputs[0] else {
            panic!("no sampled rainfall constraint");
        };
        assert_eq!((f.min, f.max), (0.0, 100.0));
        assert!(f.eval(100.0) > 0.9 && f.eval(5.0) == 0.0, "{f:?}");
        assert!(f.samples[..24].iter().all(|&s| s == 0.0), "{f:?}");
    }

    /// Forest low, bare ground high on a slope rising to the north: two
    /// classes, the bare layer constrained to the upper altitudes, and the
    /// calibrated tree predicted to cover the image's shares.
    #[test]
    fn a_two_class_slope_gives_two_layers_with_the_image_areas() {
        let field = HeightField::from_fn(32, 24, DVec2::splat(100.0), |_, r| 1000.0 + 50.0 * r as f32);
        let mut rng = SplitMix64(5);
        let image = RgbImage::from_fn(64, 48, |_, j| {
            let base: [f64; 3] = if j < 18 {
                [170.0, 150.0, 120.0]
            } else {
                [60.0, 80.0, 40.0]
            };
            image::Rgb(base.map(|c| (c + 12.0 * (rng.next_f64() - 0.5)) as u8))
        });
        let options = FromImageOptions {
            classes: ClassCount::Fixed(2),
            ..Default::default()
        };
        let generated = build_layers(&image, &field, &[None, None, None], &options).unwrap();
        let c = &generated.classification;
        assert_eq!(c.classes.len(), 2);
        assert_eq!(c.classes[usize::from(c.labels[5 * 64 + 10])].name, "bare");
        assert_eq!(c.classes[usize::from(c.labels[40 * 64 + 10])].name, "forest");
        assert!((c.fractions()[usize::from(c.labels[5 * 64 + 10])] - 0.375).abs() < 1e-9);
        let tree = generated.tree().unwrap();
        assert_eq!(tree.layers[0].layer.name, "forest");
        let bare = &tree.layers[1].layer;
        let altitude = bare.altitude.as_ref().unwrap();
        let (lo, hi) = field.min_max();
        assert!(altitude.eval(hi - 10.0) > 0.9 && altitude.eval(lo + 10.0) == 0.0);
        assert!(
            (generated.predicted[1] - 0.375).abs() < 0.05,
            "{:?}",
            generated.predicted
        );
    }
}
