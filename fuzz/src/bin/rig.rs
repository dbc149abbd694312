//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/rig -o out/rig target/debug/rig`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "toml", alpenglow::Rig::load);
    });
}
