//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/spt -o out/spt target/debug/spt`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "spt", alpenglow::files::read_spt);
    });
}
