//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/layers -o out/layers target/debug/layers`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "toml", alpenglow::LayerTree::load);
    });
}
