//! Library errors in the command line's words. The library names the
//! parameter at fault by its own name (`width`, `camera.fov_y_deg`,
//! `terrain.grid_side`, see [`alpenglow::Error::InvalidArgument`]); the
//! command line reports the flag that sets it (`--width`, `--fov-y`,
//! `--grid`).

/// A clap parse error on one line: its first line (and the next one for
/// "the following required arguments were not provided:"), with clap's
/// integer range ("-1 is not in 0..=4294967295") said in words.
pub fn clap_error_line(e: &clap::Error) -> String {
    let text = e.to_string();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let mut first = lines
        .next()
        .unwrap_or("invalid arguments")
        .trim_start_matches("error: ")
        .to_string();
    if first.ends_with(':') {
        if let Some(next) = lines.next() {
            first = format!("{first} {next}");
        }
    }
    // "-3 is not in 0..=4294967295": a lower bound only, said in words.
    if let Some(at) = first.find(" is not in ") {
        let range = &first[at + " is not in ".len()..];
        let bounds = range.split_once("..=").or_else(|| range.split_once(".."));
        if let Some((low, high)) = bounds {
            let open_ended = high.trim().parse::<u64>().is_ok_and(|h| h >= u64::from(u32::MAX));
            if let (true, Some(colon)) = (open_ended, first[..at].rfind("': ")) {
                first = format!("{}': must be {low} or more", &first[..colon]);
            }
        }
    }
    first
}

/// Library parameter → the flag that sets it. Parameters without an entry
/// are reported under their library name.
const FLAGS: &[(&str, &str)] = &[
    ("width", "--width"),
    ("height", "--height"),
    ("camera.fov_y_deg", "--fov-y"),
    ("camera.near", "--near"),
    ("camera.eye", "--eye"),
    ("camera.target", "--target"),
    ("camera.up", "--up"),
    ("camera.far", "--far"),
    ("orbit", "--orbit"),
    ("camera.pose", "--pose"),
    ("camera.rotation", "--rotation"),
    ("camera.fx", "--intrinsics"),
    ("camera.fy", "--intrinsics"),
    ("camera.cx", "--intrinsics"),
    ("camera.cy", "--intrinsics"),
    ("distortion.k1", "--distortion"),
    ("distortion.k2", "--distortion"),
    ("distortion.k3", "--distortion"),
    ("distortion.p1", "--distortion"),
    ("distortion.p2", "--distortion"),
    ("views", "--rig"),
    ("from_image.image", "--image"),
    ("from_image.classes", "--classes"),
    ("from_image.level2", "--level2"),
    ("from_image.mask", "--mask"),
    ("from_image.bins", "--bins"),
    ("from_image.value_weight", "--value-weight"),
    ("from_image.sun_azimuth_deg", "--sun-azimuth"),
    ("from_image.sun_elevation_deg", "--sun-elevation"),
    ("from_image.snow_min_altitude", "--snow-min-altitude"),
    ("msaa", "--msaa"),
    ("rocks", "--rocks"),
    ("terrain grid", "--terrain"),
    ("vegetation.density", "--vegetation-density"),
    ("shutter", "--shutter"),
    ("distortion", "--distortion"),
    ("lens.k1", "--distortion (k1)"),
    ("lens.k2", "--distortion (k2)"),
    ("lens.k3", "--distortion (k3)"),
    ("lens.p1", "--distortion (p1)"),
    ("lens.p2", "--distortion (p2)"),
    ("fps", "--fps"),
    ("view.name", "--rig"),
    ("terrain.grid_side", "--grid"),
    ("terrain.lod.sketch_side", "--sketch"),
    ("terrain.lod.snap", "--lod-snap"),
    ("terrain.detail_amplitude", "--detail-amplitude"),
    ("points.epsilon", "--epsilon"),
    ("points.primitive", "--splat-primitive"),
    ("points.kernel", "--splat-kernel"),
    ("points.error", "--spt-error"),
    ("points.transform", "--points-transform"),
    ("lighting.sun_elevation", "--sun-elevation"),
    ("lighting.sun_azimuth", "--sun-azimuth"),
    ("lighting.turbidity", "--turbidity"),
    ("lighting.exposure", "--exposure"),
    ("lighting.sh_bands", "--sh-bands"),
    ("lighting.bounces", "--bounces"),
    ("lighting.sky_patches", "--sky-patches"),
    ("lighting.albedo_override", "--albedo-override"),
    ("lighting.sky_preset", "--sky-preset"),
    ("lighting.date", "--date"),
    ("lighting.time", "--time"),
    ("lighting.latitude", "--latitude"),
    ("lighting.longitude", "--longitude"),
    ("texturing.tile_budget", "--tile-budget"),
    ("height-map scale", "--height-scale"),
    ("height-map offset", "--height-offset"),
    ("height-map spacing", "--spacing"),
];

/// The flag(s) that set library parameter `parameter`: a [`FLAGS`] entry;
/// `a/b` (two parameters at fault together) as `flag(a)/flag(b)`;
/// `input_maps.NAME` as `--input-map NAME=FILE`. None for parameters no
/// flag sets.
pub fn flag(parameter: &str) -> Option<String> {
    if let Some((a, b)) = parameter.split_once('/') {
        return Some(format!("{}/{}", flag(a)?, flag(b)?));
    }
    if let Some(name) = parameter.strip_prefix("input_maps.") {
        return Some(format!("--input-map {name}=FILE"));
    }
    FLAGS
        .iter()
        .find(|(p, _)| *p == parameter)
        .map(|(_, f)| (*f).to_owned())
}

/// A library error's message with the parameter named by its flag.
pub fn describe(e: &alpenglow::Error) -> String {
    match e {
        alpenglow::Error::InvalidArgument { parameter, message } => match flag(parameter) {
            Some(flag) => format!("invalid {flag}: {message}"),
            None => e.to_string(),
        },
        _ => e.to_string(),
    }
}

/// The one-line report of `e` and its causes (`a: b: c`), library errors
/// among them in the command line's words ([`describe`]).
pub fn error_line(e: &anyhow::Error) -> String {
    let parts: Vec<String> = e
        .chain()
        .map(|cause| match cause.downcast_ref::<alpenglow::Error>() {
            Some(e) => describe(e),
            None => cause.to_string(),
        })
        .collect();
    parts.join(": ").replace('\n', " ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use alpenglow::Camera;
    use alpenglow::Orbit;
    use alpenglow::PointTransform;
    use alpenglow::SplatSettings;
    use anyhow::Context as _;
    use glam::DVec3;

    fn camera() -> Camera {
        Camera {
            eye: DVec3::ZERO,
            target: DVec3::X,
            up: DVec3::Z,
            fov_y_deg: 50.0,
            near: 0.1,
            far: 100.0,
        }
    }

    fn line(e: alpenglow::Error) -> String {
        error_line(&anyhow::Error::from(e))
    }

    #[test]
    fn table_and_composite_names() {
        assert_eq!(flag("width").as_deref(), Some("--width"));
        assert_eq!(flag("camera.near/camera.far").as_deref(), Some("--near/--far"));
        assert_eq!(flag("camera.near/texture atlas"), None);
        assert_eq!(
            flag("input_maps.rainfall").as_deref(),
            Some("--input-map rainfall=FILE")
        );
        assert_eq!(flag("texture atlas"), None);
        let unmapped = alpenglow::Error::invalid("texture atlas", "full");
        assert_eq!(describe(&unmapped), "invalid texture atlas: full");
        let io = alpenglow::Error::input("a.png", "truncated");
        assert_eq!(describe(&io), io.to_string());
    }

    /// The library's errors, reported by the CLI, name the flags.
    #[test]
    fn library_errors_name_the_flags() {
        let cases: Vec<(alpenglow::Error, &str)> = vec![
            (
                Camera {
                    fov_y_deg: 0.0,
                    ..camera()
                }
                .validate()
                .unwrap_err(),
                "invalid --fov-y: ",
            ),
            (
                Camera {
                    near: 10.0,
                    far: 5.0,
                    ..camera()
                }
                .validate()
                .unwrap_err(),
                "invalid --near/--far: ",
            ),
            (
                Orbit {
                    centre: DVec3::ZERO,
                    radius: 0.0,
                    height: 1.0,
                    turns: 1.0,
                    start_angle_deg: 0.0,
                }
                .validate()
                .unwrap_err(),
                "invalid --orbit: ",
            ),
            (
                PointTransform::parse("s=0").unwrap_err(),
                "invalid --points-transform: ",
            ),
            (
                SplatSettings {
                    epsilon: Some(0.0),
                    ..SplatSettings::default()
                }
                .validate()
                .unwrap_err(),
                "invalid --epsilon: ",
            ),
            (
                SplatSettings {
                    kernel: alpenglow::SplatKernel::Affine,
                    primitive: alpenglow::SplatPrimitive::ObjectQuad,
                    ..SplatSettings::default()
                }
                .validate()
                .unwrap_err(),
                "invalid --splat-kernel: ",
            ),
            (
                SplatSettings {
                    error: alpenglow::SptError::ViewDependent,
                    primitive: alpenglow::SplatPrimitive::ObjectInstanced,
                    ..SplatSettings::default()
                }
                .validate()
                .unwrap_err(),
                "invalid --spt-error: ",
            ),
            (alpenglow::validate_size(0, 32).unwrap_err(), "invalid --width: "),
        ];
        for (e, start) in cases {
            let line = line(e);
            assert!(line.starts_with(start), "{line}");
        }
    }

    #[test]
    fn causes_are_described_too() {
        let e = Err::<(), _>(alpenglow::Error::invalid("camera.fov_y_deg", "0 degrees"))
            .context("camera path frame 3")
            .unwrap_err();
        assert_eq!(error_line(&e), "camera path frame 3: invalid --fov-y: 0 degrees");
        let e = anyhow::anyhow!("two\nlines");
        assert_eq!(error_line(&e), "two lines");
    }
}
