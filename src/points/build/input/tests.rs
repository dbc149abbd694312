//! Tests of the PLY reader (the OBJ reader's are in `obj`).

use super::*;
use std::path::PathBuf;

pub(super) fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// A scratch file in the system temporary directory, removed on drop.
pub(super) struct Scratch(pub(super) PathBuf);

impl Scratch {
    pub(super) fn new(name: &str, bytes: &[u8]) -> Scratch {
        let path = std::env::temp_dir().join(format!("alpenglow-points-input-{}-{name}", std::process::id()));
        std::fs::write(&path, bytes).expect("write scratch file");
        Scratch(path)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn parse(bytes: &[u8]) -> Result<PointInput> {
    read_ply(bytes, Path::new("test.ply"))
}

pub(super) fn mesh(input: PointInput) -> TriangleMesh {
    match input {
        PointInput::Mesh(m) => m,
        PointInput::Points(_) => panic!("expected a mesh"),
    }
}

fn points(input: PointInput) -> PointCloud {
    match input {
        PointInput::Points(p) => p,
        PointInput::Mesh(_) => panic!("expected points"),
    }
}

fn err(result: Result<PointInput>) -> String {
    let message = result.expect_err("expected an error").to_string();
    assert!(!message.contains('\n'), "multi-line error: {message:?}");
    message
}

/// Builds PLY payloads in either byte order.
struct Bin {
    little: bool,
    bytes: Vec<u8>,
}

impl Bin {
    fn new(header: &str, little: bool) -> Bin {
        Bin {
            little,
            bytes: header.as_bytes().to_vec(),
        }
    }
    fn put<const N: usize>(&mut self, le: [u8; N], be: [u8; N]) -> &mut Self {
        self.bytes.extend_from_slice(if self.little { &le } else { &be });
        self
    }
    fn f32(&mut self, v: f32) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
    fn f64(&mut self, v: f64) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        self.put(v.to_le_bytes(), v.to_be_bytes())
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.bytes.push(v);
        self
    }
}

const SQUARE: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];

/// A unit square as a quad plus a lone triangle, float positions, uchar
/// colours, `int` indices, in the given byte order.
fn binary_square(little: bool, vertex_count: usize) -> Vec<u8> {
    let format = if little {
        "binary_little_endian"
    } else {
        "binary_big_endian"
    };
    let header = format!(
        "ply\nformat {format} 1.0\ncomment made by the test\nelement vertex {vertex_count}\n\
         property float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         element face 2\nproperty list uchar int vertex_indices\nend_header\n"
    );
    let mut b = Bin::new(&header, little);
    for (i, p) in SQUARE.iter().enumerate() {
        b.f32(p[0]).f32(p[1]).f32(p[2]).u8(10 * i as u8).u8(20).u8(255);
    }
    b.u8(4).i32(0).i32(1).i32(2).i32(3);
    b.u8(3).i32(0).i32(2).i32(3);
    b.bytes
}

fn check_binary_square(m: &TriangleMesh) {
    let expected: Vec<Vec3> = SQUARE.iter().map(|&p| Vec3::from_array(p)).collect();
    assert_eq!(m.positions, expected);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
    assert_eq!(
        m.colors,
        Some(vec![[0, 20, 255], [10, 20, 255], [20, 20, 255], [30, 20, 255]])
    );
    assert_eq!(m.normals, None);
}

#[test]
fn ascii_ply_mesh_with_normals_from_fixture() {
    let m = mesh(load_points_file(&data("points/quad.ply")).unwrap());
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0));
    // The quad is fanned from its first vertex; the winding is kept.
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(m.normals, Some(vec![Vec3::Z; 4]));
    assert_eq!(m.colors, None);
}

#[test]
fn ascii_ply_points_with_int_and_double_coordinates() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty int x\nproperty double y\n\
                property short z\nproperty float confidence\nend_header\n1 2.5 -3 0.9\n-4 5e-1 6 1\n";
    let p = points(parse(text.as_bytes()).unwrap());
    assert_eq!(p.positions, vec![Vec3::new(1.0, 2.5, -3.0), Vec3::new(-4.0, 0.5, 6.0)]);
    assert_eq!((p.normals, p.colors, p.radii), (None, None, None));
}

#[test]
fn binary_little_endian_ply() {
    let bytes = binary_square(true, 4);
    let file = Scratch::new("le.ply", &bytes);
    check_binary_square(&mesh(load_points_file(&file.0).unwrap()));
}

#[test]
fn binary_big_endian_ply() {
    let bytes = binary_square(false, 4);
    let file = Scratch::new("be.PLY", &bytes);
    check_binary_square(&mesh(load_points_file(&file.0).unwrap()));
}

#[test]
fn binary_big_endian_doubles_uint_indices_and_extra_elements() {
    let header = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n\
                  property double y\nproperty double z\nproperty float nx\nproperty float ny\n\
                  property float nz\nelement face 1\nproperty uchar flags\n\
                  property list uchar uint vertex_index\nelement edge 1\nproperty int vertex1\n\
                  property int vertex2\nend_header\n";
    let mut b = Bin::new(header, false);
    for (p, n) in [(0.0, 2.0), (1.0, 0.0), (2.0, -1.0)] {
        b.f64(p).f64(p * 2.0).f64(1e10).f32(0.0).f32(0.0).f32(n);
    }
    b.u8(7).u8(3).u32(2).u32(1).u32(0);
    b.i32(0).i32(1);
    let m = mesh(parse(&b.bytes).unwrap());
    assert_eq!(m.positions[2], Vec3::new(2.0, 4.0, 1e10));
    assert_eq!(m.triangles, vec![[2, 1, 0]]);
    // Normalised; the zero normal stays zero ("unknown").
    assert_eq!(m.normals, Some(vec![Vec3::Z, Vec3::ZERO, -Vec3::Z]));
}

#[test]
fn ply_tristrips_with_restart_and_alternating_winding() {
    let m = mesh(load_points_file(&data("points/strip.ply")).unwrap());
    assert_eq!(m.positions.len(), 6);
    // Strip 0 1 2 3 4, restart, strip 5 4 3 (all counter-clockwise seen
    // from +z); the degenerate 4 4 5 stitch in the second strip is dropped.
    assert_eq!(m.triangles, vec![[0, 1, 2], [2, 1, 3], [2, 3, 4], [5, 4, 3]]);
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        assert!((b - a).cross(c - a).z > 0.0, "triangle {t:?} is clockwise");
    }
}

#[test]
fn ply_points_with_float_colors_and_radius() {
    let p = points(load_points_file(&data("points/colored-points.ply")).unwrap());
    assert_eq!(p.positions.len(), 3);
    assert_eq!(p.colors, Some(vec![[255, 0, 0], [0, 128, 0], [0, 0, 255]]));
    assert_eq!(p.radii, Some(vec![0.5, 0.25, 2.0]));
    assert_eq!(p.normals.as_ref().map(Vec::len), Some(3));
    assert_eq!(p.normals.unwrap()[1], Vec3::Y);
}

#[test]
fn ply_points_with_clip_lines() {
    let header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nproperty float nx\nproperty float ny\nproperty float nz\n\
                  property float clip0_angle\nproperty float clip0_offset\n\
                  property float clip1_angle\nproperty float clip1_offset\nend_header\n";
    let body = "0 0 0 0 0 1 0.5 0.1 1.0 3.4028235e38\n\
                1 0 0 0 0 1 0 0.2 1.5 -0.125\n\
                2 0 0 0 0 1 0 3.4028235e38 0 3.4028235e38\n";
    let file = Scratch::new("clip.ply", format!("{header}{body}").as_bytes());
    let p = points(load_points_file(&file.0).unwrap());
    let line = |angle, offset| Some(ClipLine { angle, offset });
    assert_eq!(
        p.clip,
        Some(vec![
            ClipLines([line(0.5, 0.1), None]),
            ClipLines([line(0.0, 0.2), line(1.5, -0.125)]),
            ClipLines::NONE,
        ])
    );
    // One line only; the other clip fields absent.
    let one = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
               property float z\nproperty double clip0_offset\nproperty float clip0_angle\n\
               end_header\n0 0 0 0.25 -1\n";
    let p = points(parse(one.as_bytes()).unwrap());
    assert_eq!(p.clip, Some(vec![ClipLines([line(-1.0, 0.25), None])]));
    // Without clip properties there are none.
    let plain = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                 property float z\nend_header\n0 0 0\n";
    assert_eq!(points(parse(plain.as_bytes()).unwrap()).clip, None);
    // An incomplete pair, a NaN, a −inf offset: errors.
    let half = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
                property float z\nproperty float clip1_angle\nend_header\n0 0 0 1\n";
    let message = err(parse(half.as_bytes()));
    assert!(message.contains("'clip1_angle' without 'clip1_offset'"), "{message}");
    // (ASCII PLY has no NaN or infinity: binary.)
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n\
                  property float y\nproperty float z\nproperty float clip0_angle\n\
                  property float clip0_offset\nend_header\n";
    for (angle, offset) in [(f32::NAN, 0.1), (0.5, f32::NEG_INFINITY), (f32::INFINITY, 0.1)] {
        let mut b = Bin::new(header, true);
        b.f32(0.0).f32(0.0).f32(0.0).f32(0.0).f32(0.1);
        b.f32(1.0).f32(1.0).f32(1.0).f32(angle).f32(offset);
        let message = err(parse(&b.bytes));
        assert!(message.contains("vertex 1 has a non-finite clip line"), "{message}");
    }
    // An infinite offset is no line, whatever the angle.
    let mut b = Bin::new(header, true);
    b.f32(0.0).f32(0.0).f32(0.0).f32(f32::NAN).f32(f32::INFINITY);
    b.f32(1.0).f32(1.0).f32(1.0).f32(0.0).f32(0.5);
    assert_eq!(
        points(parse(&b.bytes).unwrap()).clip,
        Some(vec![ClipLines::NONE, ClipLines([line(0.0, 0.5), None])])
    );
    // Meshes ignore them.
    let mesh_text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                     property float z\nproperty float clip0_angle\nproperty float clip0_offset\n\
                     element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                     0 0 0 0 -7\n1 0 0 0 0\n0 1 0 0 0\n3 0 1 2\n";
    assert_eq!(mesh(parse(mesh_text.as_bytes()).unwrap()).triangles.len(), 1);
}

#[test]
fn ply_radius_must_be_positive() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                property float z\nproperty float radius\nend_header\n0 0 0 1\n1 1 1 0\n";
    let message = err(parse(text.as_bytes()));
    assert!(message.contains("vertex 1 has radius 0"), "{message}");
}

#[test]
fn truncated_binary_ply_is_an_error_at_every_length() {
    for little in [true, false] {
        let bytes = binary_square(little, 4);
        assert!(parse(&bytes).is_ok());
        for len in 0..bytes.len() {
            let message = err(parse(&bytes[..len]));
            assert!(message.starts_with("test.ply: "), "{message}");
        }
    }
}

#[test]
fn corrupted_ply_never_panics() {
    // Flip random bytes (a fixed linear congruential sequence) in binary
    // and ASCII files; every outcome must be a result, not a panic.
    let ascii = std::fs::read(data("points/strip.ply")).unwrap();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as usize
    };
    for original in [binary_square(true, 4), binary_square(false, 4), ascii] {
        for _ in 0..400 {
            let mut bytes = original.clone();
            for _ in 0..1 + next() % 4 {
                let i = next() % bytes.len();
                bytes[i] = next() as u8;
            }
            if let Err(e) = parse(&bytes) {
                assert!(!e.to_string().contains('\n'));
            }
        }
    }
}

#[test]
fn header_counts_that_lie_are_errors() {
    // Too many vertices: the faces are read as a vertex, the rest fails.
    let message = err(parse(&binary_square(true, 5)));
    assert!(message.starts_with("test.ply: "), "{message}");
    // Too few: data is left over after the last element.
    let message = err(parse(&binary_square(false, 3)));
    assert!(message.starts_with("test.ply: "), "{message}");
    // The same in ASCII, with the checked-in fixture.
    let message = err(load_points_file(&data("points/short-count.ply")));
    assert!(
        message.contains("short-count.ply: data after the last PLY element"),
        "{message}"
    );
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nend_header\n0 0 0\n1 1 1\n";
    let message = err(parse(text.as_bytes()));
    assert!(message.contains("need at least 18 bytes, but only 12"), "{message}");
    // Enough bytes for the count, too few values: the parser's error.
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nend_header\n0 0 0\n1.5 1.5 1.5\n";
    let message = err(parse(text.as_bytes()));
    assert!(message.contains("Unexpected end of file"), "{message}");
}

#[test]
fn bad_face_index_is_an_error_naming_face_and_vertex() {
    let message = err(load_points_file(&data("points/bad-index.ply")));
    assert!(
        message.ends_with("bad-index.ply: face 1 refers to vertex 9001 of 4"),
        "{message}"
    );
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement tristrips 1\nproperty list int int vertex_indices\n\
                end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2 -2\n";
    let message = err(parse(text.as_bytes()));
    assert_eq!(message, "test.ply: triangle strip 0 refers to vertex -2 of 3");
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n";
    let message = err(parse(text.as_bytes()));
    assert_eq!(message, "test.ply: face 0 has 2 vertices (at least 3 needed)");
}

/// A PLY file: header lines between the format and `end_header`, then `body`.
fn ply(format: &str, header: &str, body: &[u8]) -> Vec<u8> {
    let mut bytes = format!("ply\nformat {format} 1.0\n{header}end_header\n").into_bytes();
    bytes.extend_from_slice(body);
    bytes
}

const XYZ: &str = "property float x\nproperty float y\nproperty float z\n";

#[test]
fn malformed_ply_headers_and_values_are_errors() {
    let vertex = |count: &str| format!("element vertex {count}\n{XYZ}");
    let list_x = "element vertex 1\nproperty list uchar float x\nproperty float y\nproperty float z\n";
    let float_list = format!(
        "{}element face 1\nproperty list uchar float vertex_indices\n",
        vertex("3")
    );
    let no_z = "element vertex 1\nproperty float x\nproperty float y\n";
    let cases: [(Vec<u8>, &str); 8] = [
        (Vec::new(), "invalid PLY"),
        (b"not a ply file\n".to_vec(), "invalid PLY"),
        (ply("ascii", &vertex("0"), b""), "no vertices"),
        (
            ply("ascii", "element point 1\nproperty float x\n", b"1\n"),
            "no 'vertex' element",
        ),
        (ply("ascii", no_z, b"1 2\n"), "no property 'z'"),
        (ply("ascii", &vertex("1"), b"1 2 x\n"), "invalid PLY"),
        (ply("ascii", list_x, b"1 1 2 3\n"), "'x' is a list"),
        (
            ply("ascii", &float_list, b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
            "not a list of integers",
        ),
    ];
    for (bytes, expected) in &cases {
        let message = err(parse(bytes));
        assert!(message.contains(expected), "{message:?} lacks {expected:?}");
    }

    let nan: Vec<u8> = f32::NAN.to_le_bytes().into_iter().chain([0; 8]).collect();
    let message = err(parse(&ply("binary_little_endian", &vertex("1"), &nan)));
    assert_eq!(message, "test.ply: vertex 0 has a non-finite coordinate (NaN, 0, 0)");
    let doubles = "element vertex 1\nproperty double x\nproperty double y\nproperty double z\n";
    let huge: Vec<u8> = [1e300f64, 0.0, 0.0].iter().flat_map(|v| v.to_be_bytes()).collect();
    let message = err(parse(&ply("binary_big_endian", doubles, &huge)));
    assert_eq!(message, "test.ply: vertex 0 has a non-finite coordinate (inf, 0, 0)");
}

#[test]
fn absurd_ply_counts_are_errors_without_huge_allocations() {
    for count in ["18446744073709551615", "99999999999999999999999"] {
        let message = err(parse(&ply(
            "binary_little_endian",
            &format!("element vertex {count}\n{XYZ}"),
            b"",
        )));
        let limit = message.contains("more than the limit");
        assert!(message.starts_with("test.ply: invalid PLY: ") || limit, "{message}");
    }
    let header = format!("element vertex 1\n{XYZ}element face 1\nproperty list uint int vertex_indices\n");
    let body: Vec<u8> = [0u8; 12]
        .into_iter()
        .chain(u32::MAX.to_le_bytes())
        .chain([0; 12])
        .collect();
    let message = err(parse(&ply("binary_little_endian", &header, &body)));
    assert!(message.starts_with("test.ply: invalid PLY: "), "{message}");
    // A parser message quoting a long line is cut to one short line.
    let long = format!("{} x\n", "1 ".repeat(5000));
    let message = err(parse(&ply(
        "ascii",
        &format!("element vertex 1\n{XYZ}"),
        long.as_bytes(),
    )));
    assert!(message.len() < 300, "{message}");
}

#[test]
fn unknown_extension_and_missing_file_are_errors() {
    let message = load_points_file(Path::new("scan.xyz")).unwrap_err().to_string();
    assert_eq!(
        message,
        "scan.xyz: unsupported point input file type (accepted extensions: .ply, .obj)"
    );
    let message = load_points_file(Path::new("no-extension")).unwrap_err().to_string();
    assert!(message.starts_with("no-extension: unsupported"), "{message}");
    let message = load_points_file(Path::new("/nonexistent/bunny.ply"))
        .unwrap_err()
        .to_string();
    assert!(message == "/nonexistent/bunny.ply: file not found", "{message}");
}

#[test]
fn ply_format_version_other_than_1_0_is_an_error() {
    for version in ["2.0", "1.1", "0.9"] {
        let text = format!("ply\nformat ascii {version}\nelement vertex 1\n{XYZ}end_header\n0 0 0\n");
        let message = err(parse(text.as_bytes()));
        assert_eq!(
            message,
            format!("test.ply: unsupported PLY format version {version} (only 1.0 is defined)")
        );
    }
}

#[test]
fn ply_counts_are_checked_against_the_file_size_and_the_limit() {
    // 1000 binary vertices need 12000 bytes; 12 follow.
    let body = [0u8; 12];
    let message = err(parse(&ply(
        "binary_little_endian",
        &format!("element vertex 1000\n{XYZ}"),
        &body,
    )));
    assert_eq!(
        message,
        "test.ply: the PLY header's element counts need at least 12000 bytes, but only 12 follow the header"
    );
    // Faces count too: 4 list counts of one byte each beyond the vertices.
    let header = format!("element vertex 1\n{XYZ}element face 4\nproperty list uchar int vertex_indices\n");
    let message = err(parse(&ply("binary_big_endian", &header, &body)));
    assert!(message.contains("need at least 16 bytes, but only 12"), "{message}");
    // ASCII: two characters per value at least; exactly enough passes.
    let message = err(parse(&ply("ascii", &format!("element vertex 5\n{XYZ}"), b"0 0 0\n")));
    assert!(message.contains("need at least 30 bytes, but only 6"), "{message}");
    assert!(parse(&ply("ascii", &format!("element vertex 1\n{XYZ}"), b"0 0 0")).is_ok());
    // Above the documented maximum, whatever the file size.
    let message = err(parse(&ply(
        "binary_little_endian",
        &format!("element vertex {}\n{XYZ}", MAX_PLY_ELEMENTS + 1),
        &body,
    )));
    assert!(message.contains("more than the limit of 100000000"), "{message}");
    let junk = format!("element vertex 1\n{XYZ}element junk 4000000000\nproperty uchar a\n");
    let message = err(parse(&ply("ascii", &junk, b"0 0 0\n")));
    assert!(message.contains("'junk' has 4000000000 entries"), "{message}");
}

#[test]
fn non_finite_ply_colours_name_the_vertex() {
    let header = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n\
                  property float y\nproperty float z\nproperty float red\nproperty float green\n\
                  property double blue\nend_header\n";
    for (green, blue) in [(f32::NAN, 0.5), (0.5, f64::INFINITY), (f32::NEG_INFINITY, 0.0)] {
        let mut b = Bin::new(header, true);
        b.f32(0.0).f32(0.0).f32(0.0).f32(1.0).f32(0.0).f64(0.0);
        b.f32(1.0).f32(1.0).f32(1.0).f32(1.0).f32(green).f64(blue);
        assert_eq!(err(parse(&b.bytes)), "test.ply: vertex 1 has a non-finite colour");
    }
    let mut b = Bin::new(header, true);
    b.f32(0.0).f32(0.0).f32(0.0).f32(1.0).f32(0.0).f64(0.0);
    b.f32(1.0).f32(1.0).f32(1.0).f32(2.0).f32(-1.0).f64(0.5);
    // Finite values out of 0–1 are clamped, as documented.
    assert_eq!(points(parse(&b.bytes).unwrap()).colors.unwrap()[1], [255, 0, 128]);
}

#[test]
fn ply_files_are_read_through_read_input() {
    let dir = std::env::temp_dir().join(format!("alpenglow-ply-dir-{}.ply", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let message = load_points_file(&dir).unwrap_err().to_string();
    assert!(message.contains("is a directory"), "{message}");
    std::fs::remove_dir_all(&dir).unwrap();
}
