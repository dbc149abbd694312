//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/keyframes -o out/keyframes target/debug/keyframes`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "toml", alpenglow::view::camera_path::load_keyframes);
    });
}
