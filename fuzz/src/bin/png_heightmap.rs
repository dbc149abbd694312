//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/png -o out/png_heightmap target/debug/png_heightmap`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "png", |p| {
            alpenglow::files::load_heightmap(p, &alpenglow::HeightmapOptions::default())
        });
    });
}
