//! The dominant surface layer of a point (the terrain's semantic class,
//! `crate::view::aov`): the layer with the largest final share of the
//! point's colour. In the depth-first blend of §8.2 each layer S sets
//! `RGB = (1 − C_S)·RGB_in + C_S·RGB_S`, so layer k contributes
//! `C_k · Π_{j>k} (1 − C_j)`: every later layer blends over it. The first
//! of equal shares wins (a child covering half of its parent ties with it
//! and leaves the parent dominant).
//!
//! The shaders (`glsl/include/surface_layers.glsl`) track it along the walk
//! without keeping every share: all earlier shares scale by the same
//! `1 − C_j`, so the running best keeps its place among them and only the
//! new layer's own share `C_j` can overtake it ([`dominant_layer_running`]).

/// The share of each layer in the final colour of a depth-first blend with
/// coverages `coverage` (`C_k · Π_{j>k} (1 − C_j)`).
pub fn layer_shares(coverage: &[f32]) -> Vec<f32> {
    let mut shares = vec![0.0; coverage.len()];
    let mut above = 1.0;
    for (k, &c) in coverage.iter().enumerate().rev() {
        shares[k] = c * above;
        above *= 1.0 - c;
    }
    shares
}

/// The dominant layer of a blend with coverages `coverage`: the largest
/// share, the first of equal ones (None for no layers).
pub fn dominant_layer(coverage: &[f32]) -> Option<usize> {
    let shares = layer_shares(coverage);
    let mut best: Option<usize> = None;
    for (k, &s) in shares.iter().enumerate() {
        if best.map_or(true, |b| s > shares[b]) {
            best = Some(k);
        }
    }
    best
}

/// The dominant layer as the shaders track it along the walk: the running
/// best's share scaled by every later layer's `1 − C`, a later layer taking
/// over when its own coverage is larger.
#[cfg(test)]
pub fn dominant_layer_running(coverage: &[f32]) -> Option<usize> {
    let (mut best, mut share) = (None, 0.0f32);
    for (k, &c) in coverage.iter().enumerate() {
        share *= 1.0 - c;
        if best.is_none() || c > share {
            (best, share) = (Some(k), c);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;

    #[test]
    fn shares_sum_to_the_covered_part() {
        let c = [1.0, 0.5, 0.25, 0.0];
        let s = layer_shares(&c);
        assert_eq!(s, vec![0.375, 0.375, 0.25, 0.0]);
        assert!((s.iter().sum::<f32>() - 1.0).abs() < 1e-6);
        // Equal shares: the first (the parent) wins.
        assert_eq!(dominant_layer(&c), Some(0));
        assert_eq!(dominant_layer(&[1.0, 0.6]), Some(1));
        assert_eq!(dominant_layer(&[]), None);
    }

    #[test]
    fn the_running_maximum_is_the_largest_share() {
        let mut rng = SplitMix64(7);
        for _ in 0..2000 {
            let n = 1 + (rng.next_u64() % 8) as usize;
            let mut c: Vec<f32> = (0..n)
                .map(|_| match rng.next_u64() % 4 {
                    0 => 0.0,
                    1 => 1.0,
                    _ => rng.next_f64() as f32,
                })
                .collect();
            c[0] = 1.0;
            let shares = layer_shares(&c);
            let (exact, running) = (dominant_layer(&c).unwrap(), dominant_layer_running(&c).unwrap());
            // Equal up to the rounding of nearly tied shares.
            assert!(
                exact == running || (shares[exact] - shares[running]).abs() < 1e-6,
                "{c:?}: {exact} vs {running}"
            );
        }
    }
}
