//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/keyframes -o out/keyframes target/debug/keyframes`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "toml", alpenglow::files::load_keyframes);
    });
}
