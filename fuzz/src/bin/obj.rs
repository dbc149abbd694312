//! AFL++ target: `cargo afl fuzz -i ../tests/data/fuzz/obj -o out/obj target/debug/obj`.

fn main() {
    afl::fuzz!(|data: &[u8]| {
        alpenglow_fuzz::run(data, "obj", alpenglow::files::load_points_file);
    });
}
