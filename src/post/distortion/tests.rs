use super::*;
use crate::view::lens::{Distortion, Intrinsics};

fn camera(lens: Distortion) -> DistortedCamera {
    DistortedCamera {
        intrinsics: Intrinsics::centred(150.0, 150.0, 64, 48),
        lens,
        width: 64,
        height: 48,
    }
}

const BARREL: Distortion = Distortion {
    k1: -0.28,
    k2: 0.07,
    k3: 0.0,
    p1: 0.001,
    p2: -0.0005,
};

const PINCUSHION: Distortion = Distortion {
    k1: 0.22,
    k2: 0.05,
    k3: 0.01,
    p1: -0.002,
    p2: 0.001,
};

#[test]
fn zero_coefficients_give_the_identity() {
    let camera = camera(Distortion::default());
    let source = source_intrinsics(&camera).unwrap();
    assert_eq!((source.width, source.height), (64, 48));
    assert_eq!(source.intrinsics, camera.intrinsics);
    let map = source_map(&camera, &source).unwrap();
    for (n, q) in map.positions.iter().enumerate() {
        assert_eq!(*q, [(n % 64) as f32, (n / 64) as f32]);
    }
    let fov = 2.0 * (24.0f64 / 150.0).atan().to_degrees();
    assert!((source.fov_y_deg() - fov).abs() < 1e-12);
}

#[test]
fn newton_inverts_the_distortion_and_the_jacobian_is_its_derivative() {
    for lens in [BARREL, PINCUSHION] {
        for p in [[0.0, 0.0], [0.3, -0.1], [-0.25, 0.2], [0.05, 0.31]] {
            let d = lens.distort(p);
            let back = lens.undistort(d).unwrap();
            assert!(
                (back[0] - p[0]).abs() < 1e-11 && (back[1] - p[1]).abs() < 1e-11,
                "{p:?}"
            );
            let (h, j) = (1e-6, lens.jacobian(p));
            for axis in 0..2 {
                let mut q = p;
                q[axis] += h;
                let (a, b) = (lens.distort(q), d);
                for row in 0..2 {
                    let fd = (a[row] - b[row]) / h;
                    assert!(
                        (fd - j[row][axis]).abs() < 1e-5,
                        "{p:?} {row} {axis}: {fd} vs {}",
                        j[row][axis]
                    );
                }
            }
        }
    }
}

#[test]
fn the_source_render_covers_the_output_at_its_pixel_density() {
    for lens in [BARREL, PINCUSHION] {
        let camera = camera(lens);
        let source = source_intrinsics(&camera).unwrap();
        let k = source.intrinsics;
        assert_eq!(k.fx, k.fy);
        assert_eq!(
            (k.cx, k.cy),
            ((source.width as f64 - 1.0) / 2.0, (source.height as f64 - 1.0) / 2.0)
        );
        let map = source_map(&camera, &source).unwrap();
        let at = |i: u32, j: u32| map.positions[(j * 64 + i) as usize];
        let mut smallest = f32::MAX;
        for j in 0..47 {
            for i in 0..63 {
                let (p, r, d) = (at(i, j), at(i + 1, j), at(i, j + 1));
                smallest = smallest.min(r[0] - p[0]).min(d[1] - p[1]);
            }
        }
        // The stretch is at least 1 (to the discrete derivative's error) and
        // not far above (the render is no larger than it needs to be).
        assert!(smallest > 0.99 && smallest < 1.2, "{lens:?}: {smallest}");
        let inside = map.positions.iter().all(|q| {
            (-0.5..=source.width as f32 - 0.5).contains(&q[0]) && (-0.5..=source.height as f32 - 0.5).contains(&q[1])
        });
        assert!(inside);
    }
    // Pincushion compresses the edges: a larger, denser render; barrel a wider one.
    let pin = source_intrinsics(&camera(PINCUSHION)).unwrap();
    assert!(pin.intrinsics.fx > 150.0);
    let barrel = source_intrinsics(&camera(BARREL)).unwrap();
    assert!((barrel.intrinsics.fx - 150.0).abs() < 0.01, "{barrel:?}");
    assert!(barrel.width > 64 && barrel.height > 48);
}

fn error_of(result: Result<SourceView>) -> String {
    let e = result.unwrap_err().to_string();
    assert!(!e.contains('\n'), "{e}");
    e
}

#[test]
fn bad_lenses_are_errors_naming_the_coefficient() {
    let with = |f: fn(&mut Distortion)| {
        let mut lens = Distortion::default();
        f(&mut lens);
        source_intrinsics(&camera(lens))
    };
    assert!(error_of(with(|l| l.k2 = f64::NAN)).contains("lens.k2"));
    assert!(error_of(with(|l| l.p1 = 2.0)).contains("lens.p1"));
    assert!(error_of(with(|l| l.k3 = -11.0)).contains("lens.k3"));
    // Strong barrel on a wide lens: the radial mapping peaks inside the image.
    let wide = |lens: Distortion| DistortedCamera {
        intrinsics: Intrinsics::centred(40.0, 40.0, 64, 48),
        ..camera(lens)
    };
    let fold = Distortion {
        k1: -0.5,
        ..Default::default()
    };
    assert!(error_of(source_intrinsics(&wide(fold))).contains("lens.k1"));
    // Folds and comes back (k2 > 0): a wrong root past the fold is rejected.
    let back = Distortion {
        k1: -0.6,
        k2: 0.1,
        ..Default::default()
    };
    let e = error_of(source_intrinsics(&wide(back)));
    assert!(e.contains("lens.k") && e.contains("folds"), "{e}");
}

#[test]
fn bad_cameras_and_small_sources_are_errors_naming_them() {
    let mut bad = camera(BARREL);
    bad.intrinsics.fx = 0.0;
    assert!(error_of(source_intrinsics(&bad)).contains("distortion intrinsics.fx"));
    bad = camera(BARREL);
    bad.width = 0;
    assert!(error_of(source_intrinsics(&bad)).contains("distortion width"));
    let own = SourceView {
        intrinsics: camera(PINCUSHION).intrinsics,
        width: 64,
        height: 48,
    };
    let e = source_map(&camera(BARREL), &own).unwrap_err().to_string();
    assert!(e.contains("distortion source") && !e.contains('\n'), "{e}");
}
