//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/exr -o out/exr_heightmap target/debug/exr_heightmap`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "exr", |p| {
            alpenglow::files::load_heightmap(p, &alpenglow::HeightmapOptions::default())
        });
    });
}
