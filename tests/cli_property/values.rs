//! Random and extreme values of the numeric options: NaN, ±inf, 0, -0,
//! negatives, huge (1e308, 1e30, u64::MAX + 1), tiny (1e-300), each
//! documented limit and just beyond it, random valid values, and for
//! comma lists wrong counts and one bad element among valid ones.

use super::options::{Kind, Special};

/// A small deterministic generator (splitmix64).
pub struct Rng(pub u64);

pub fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Rng {
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(1);
        splitmix64(self.0)
    }

    /// A number in `0..n`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    /// A float in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }

    /// A float in [lo, hi].
    pub fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// Values that break naive parsing and range checks of any float.
const FLOAT_EXTREMES: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "infinity",
    "0",
    "-0",
    "-1",
    "1",
    "1e308",
    "-1e308",
    "1e30",
    "-1e30",
    "1e-300",
    "-1e-300",
    "1e309",
    "18446744073709551616",
    "3.5e38",
    "1e-45",
];

/// Values that break naive parsing and range checks of any integer.
const INT_EXTREMES: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1",
    "2147483647",
    "4294967295",
    "4294967296",
    "9223372036854775807",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "-9223372036854775809",
    "1e3",
    "1.5",
    "nan",
    "",
];

/// A float printed the way a user would type it (shortest round trip).
fn show(v: f64) -> String {
    format!("{v}")
}

/// `v` just beyond a limit (`dir` −1 below, +1 above).
fn beyond(v: f64, dir: f64) -> f64 {
    let step = (v.abs() * 1e-6).max(1e-9);
    v + dir * step
}

/// A value in or around `lo..=hi` (random valid below `cheap`, the limits,
/// just beyond them, or an extreme).
pub fn float(rng: &mut Rng, lo: f64, hi: f64, cheap: f64) -> String {
    let top = hi.min(cheap);
    match rng.below(10) {
        0..=2 => rng.pick(FLOAT_EXTREMES).to_string(),
        3 => show(lo),
        4 => show(if hi <= cheap { hi } else { top }),
        5 => show(beyond(lo, -1.0)),
        6 => show(beyond(hi, 1.0)),
        7 => {
            // Log-uniform magnitude, either sign.
            let m = 10f64.powf(rng.between(-8.0, 8.0));
            show(if rng.chance(0.5) { m } else { -m })
        }
        _ => show(rng.between(lo.max(-1e6), top.min(1e6))),
    }
}

/// An integer in or around `lo..=hi`.
pub fn int(rng: &mut Rng, lo: i128, hi: i128, cheap: i128) -> String {
    let top = hi.min(cheap);
    match rng.below(10) {
        0..=2 => rng.pick(INT_EXTREMES).to_string(),
        3 => lo.to_string(),
        4 => top.to_string(),
        5 => (lo - 1).to_string(),
        6 => (hi + 1).to_string(),
        _ => {
            let span = (top - lo).clamp(0, 1 << 20) as u64;
            (lo + (rng.next() % (span + 1)) as i128).to_string()
        }
    }
}

/// Comma-separated floats: usually a valid count with one element
/// extreme, sometimes a wrong count or an empty element.
pub fn list(rng: &mut Rng, counts: &[usize], lo: f64, hi: f64) -> String {
    let mut n = *rng.pick(counts);
    if rng.chance(0.1) {
        n = if rng.chance(0.5) { n + 1 } else { n.saturating_sub(1) };
    }
    let mut parts: Vec<String> = (0..n).map(|_| show(rng.between(lo, hi))).collect();
    if !parts.is_empty() && rng.chance(0.6) {
        let k = rng.below(parts.len());
        parts[k] = float(rng, lo, hi, hi);
    }
    if rng.chance(0.03) {
        parts.push(String::new());
    }
    parts.join(",")
}

/// A value of `kind`.
pub fn value(rng: &mut Rng, kind: Kind) -> String {
    match kind {
        Kind::Int { lo, hi, cheap } => int(rng, lo, hi, cheap),
        Kind::OneOf(set) => match rng.below(4) {
            0 => rng.pick(INT_EXTREMES).to_string(),
            1 => (set[set.len() - 1] + 1 + rng.below(3) as i128).to_string(),
            _ => rng.pick(set).to_string(),
        },
        Kind::Float { lo, hi, cheap } => float(rng, lo, hi, cheap),
        Kind::List { n, lo, hi } => list(rng, n, lo, hi),
        Kind::Special(s) => special(rng, s),
    }
}

fn special(rng: &mut Rng, s: Special) -> String {
    match s {
        Special::Pose => pose(rng),
        Special::Rotation => {
            let q: Vec<f64> = (0..4).map(|_| rng.between(-1.0, 1.0)).collect();
            let len = q.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-9);
            let mut parts: Vec<String> = q.iter().map(|x| show(x / len)).collect();
            if rng.chance(0.5) {
                let k = rng.below(4);
                parts[k] = float(rng, -1.0, 1.0, 1.0);
            }
            parts.join(",")
        }
        Special::Terrain => terrain(rng),
        Special::Transform => {
            let t = list(rng, &[3], -1e3, 1e3);
            let r = list(rng, &[3], -360.0, 360.0);
            let s = float(rng, 1e-3, 1e3, 1e3);
            match rng.below(4) {
                0 => format!("t={t}"),
                1 => format!("r={r}"),
                2 => format!("s={s}"),
                _ => format!("t={t};r={r};s={s}"),
            }
        }
        Special::Date => {
            let y = int(rng, 1, 9999, 9999);
            let m = int(rng, 1, 12, 12);
            let d = int(rng, 1, 31, 31);
            format!("{y}-{m}-{d}")
        }
        Special::Time => format!("{}:{}", int(rng, 0, 23, 23), int(rng, 0, 59, 59)),
        Special::Exposure => {
            if rng.chance(0.1) {
                "auto".into()
            } else {
                float(rng, -10.0, 30.0, 30.0)
            }
        }
        Special::Classes => {
            if rng.chance(0.1) {
                "auto".into()
            } else {
                int(rng, 1, 8, 8)
            }
        }
    }
}

/// A camera→world matrix (a rotation about z, tilted, and a position),
/// one element replaced by an extreme half of the time.
fn pose(rng: &mut Rng) -> String {
    let yaw = rng.between(0.0, std::f64::consts::TAU);
    let (s, c) = yaw.sin_cos();
    // Camera x right, y up (world z), looking down −z (world forward).
    let forward = [s, c, 0.0];
    let right = [c, -s, 0.0];
    let up = [0.0, 0.0, 1.0];
    let pos = [rng.between(-1e3, 1e3), rng.between(-1e3, 1e3), rng.between(100.0, 2e3)];
    let mut m = [0.0f64; 16];
    for row in 0..3 {
        m[row * 4] = right[row];
        m[row * 4 + 1] = up[row];
        m[row * 4 + 2] = -forward[row];
        m[row * 4 + 3] = pos[row];
    }
    m[15] = 1.0;
    let mut parts: Vec<String> = m.iter().map(|v| show(*v)).collect();
    if rng.chance(0.6) {
        let k = rng.below(16);
        parts[k] = float(rng, -1e8, 1e8, 1e8);
    }
    parts.join(",")
}

/// A procedural terrain spec: small by default, one or two keys varied.
fn terrain(rng: &mut Rng) -> String {
    let model = *rng.pick(&["fbm", "multifractal", "heterogeneous", "hybrid", "ridged"]);
    let mut keys: Vec<(&str, String)> = Vec::new();
    for _ in 0..1 + rng.below(2) {
        let key = *rng.pick(&[
            "seed",
            "octaves",
            "lacunarity",
            "h",
            "offset",
            "gain",
            "wavelength",
            "amplitude",
            "size",
            "spacing",
        ]);
        if keys.iter().any(|(k, _)| *k == key) {
            continue;
        }
        let v = match key {
            "seed" => int(rng, 0, u64::MAX as i128, u64::MAX as i128),
            "octaves" => int(rng, 1, 16, 16),
            "size" => {
                let a = int(rng, 2, 8193, 129);
                if rng.chance(0.3) {
                    format!("{a}:{}", int(rng, 2, 8193, 129))
                } else {
                    a
                }
            }
            "spacing" => {
                let a = float(rng, 0.001, 100000.0, 100000.0);
                if rng.chance(0.3) {
                    format!("{a}:{}", float(rng, 0.001, 100000.0, 100000.0))
                } else {
                    a
                }
            }
            _ => float(rng, -1e4, 1e4, 1e4),
        };
        keys.push((key, v));
    }
    if !keys.iter().any(|(k, _)| *k == "size") {
        keys.push(("size", "33".into()));
    }
    let body: Vec<String> = keys.iter().map(|(k, v)| format!("{k}={v}")).collect();
    format!("procedural:{model},{}", body.join(","))
}
