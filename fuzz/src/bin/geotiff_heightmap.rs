//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/geotiff -o out/geotiff_heightmap target/debug/geotiff_heightmap`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "tif", |p| {
            alpenglow::files::load_heightmap(p, &alpenglow::HeightmapOptions::default())
        });
    });
}
