//! Writes one procedural rock (dissertation §6.1.4) as an OBJ mesh, by
//! default the text's rock of Fig. 10.11: 8 hull points and 7 rounds of
//! subdivision, 12 · 4⁷ = 196 608 triangles:
//! `cargo run --release --example rock_obj -- OUT.obj [--seed N]
//! [--points N] [--subdivisions N]`. Then `alpenglow spt build OUT.obj
//! ROCK.spt --samples N` and `alpenglow render --points ROCK.spt --epsilon
//! PX …` draw its point tree (docs/FIGURES.md, Fig. 10.11).

use alpenglow::tools::spt::{generate_rock, write_obj, RockParams};

fn main() {
    let mut args = std::env::args().skip(1);
    let mut out = None;
    let mut params = RockParams {
        points: 8,
        subdivisions: 7,
        ..RockParams::default()
    };
    while let Some(arg) = args.next() {
        let mut value = |name: &str| -> u64 {
            let v = args.next().unwrap_or_else(|| fail(&format!("{name} needs a value")));
            v.parse()
                .unwrap_or_else(|_| fail(&format!("invalid {name}: {v} is not a count")))
        };
        match arg.as_str() {
            "--seed" => params.seed = value("--seed"),
            "--points" => params.points = value("--points").min(u64::from(u32::MAX)) as u32,
            "--subdivisions" => params.subdivisions = value("--subdivisions").min(u64::from(u32::MAX)) as u32,
            _ if out.is_none() && !arg.starts_with("--") => out = Some(std::path::PathBuf::from(arg)),
            _ => fail(&format!("unexpected argument {arg}")),
        }
    }
    let out = out.unwrap_or_else(|| fail("usage: rock_obj OUT.obj [--seed N] [--points N] [--subdivisions N]"));
    let mesh = generate_rock(&params).unwrap_or_else(|e| fail(&e.to_string()));
    write_obj(&mesh, &out).unwrap_or_else(|e| fail(&e.to_string()));
    println!(
        "{}: {} triangles, {} vertices (seed {}, {} points, {} subdivisions)",
        out.display(),
        mesh.triangles.len(),
        mesh.positions.len(),
        params.seed,
        params.points,
        params.subdivisions
    );
}

fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(2);
}
