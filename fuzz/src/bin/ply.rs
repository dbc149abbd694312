//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/ply -o out/ply target/debug/ply`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "ply", alpenglow::files::load_points_file);
    });
}
