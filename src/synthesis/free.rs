//! Free synthesis (dissertation §7.3.2, Fig. 7.1: "height fields
//! synthesized by non-parametric sampling" without user constraints): a
//! new field of a requested size grown from an exemplar height field
//! alone, Efros–Leung as the text describes it for textures.
//!
//! Decisions:
//! * **Seed**: the growth starts from one n×n window (n = `--window`) of
//!   the exemplar, at a position drawn from `SplitMix64(seed)`, pasted at
//!   the centre of the new field; everything else is unknown and grown by
//!   [`crate::synthesis::fill::Growth`] (most known neighbours first, in
//!   waves; the same search, CPU twin or GPU passes, and the same pasting
//!   with the best-fitting height offset).
//! * **Channels and normalisation**: the exemplar's (`super::exemplar`),
//!   computed once over the whole exemplar; the new field's texels are
//!   copies of exemplar texels.
//! * **Candidates**: every window inside the exemplar, or, where there are
//!   more than `--candidates`, that many chosen by a hash of the seed
//!   (`super::exemplar::nearest_candidates` with equal distances).
//! * **Spacing**: the exemplar's.
//! * **One sample a wave** by default ([`FREE_GROWTH`], `--batch 1`, the
//!   text's sequential order): in a wave of many samples, neighbours along
//!   the front are matched against the state before the wave, each
//!   without the other, and pick unrelated candidates. In a hole the
//!   fronts are short and meet known ground; a free growth is all front,
//!   and waves of 256 left speckle across the whole field in its
//!   hillshade (slope KS 0.07 but incoherent ridges), gone with waves of
//!   one (`src/synthesis/tests/free.rs` writes the hillshade).
//!
//! Deterministic for a seed: the seed window, the candidate subsample and
//! the search's choices all derive from it.

use crate::error::{Error, Result};
use crate::io::heightmap::HeightField;
use crate::random::SplitMix64;
use crate::synthesis::exemplar::{nearest_candidates, slopes, texels, Normalisation};
use crate::synthesis::fill::{FillParams, Growth};
use crate::synthesis::search::Exemplar;

/// The parameters of a free growth: those of hole filling, one sample a
/// wave (module docs).
pub const FREE_GROWTH: FillParams = FillParams {
    window: 7,
    lambda: 0.25,
    epsilon: 0.1,
    seed: 1,
    batch: 1,
    candidates: 16384,
};

/// Largest side of a grown field, in samples.
pub const MAX_SIDE: u32 = 8192;

/// Checks the exemplar and the requested size (one-line errors naming
/// `exemplar`, `--size` or the growth parameter).
pub fn check_free_growth(exemplar: &HeightField, columns: u32, rows: u32, params: &FillParams) -> Result<()> {
    if let Some(i) = exemplar.heights.iter().position(|h| !h.is_finite()) {
        return Err(Error::invalid(
            "exemplar",
            format!(
                "sample at column {}, row {} is not finite (fill its voids first: synth fill)",
                i as u32 % exemplar.columns.max(1),
                i as u32 / exemplar.columns.max(1)
            ),
        ));
    }
    params.validate(exemplar.columns, exemplar.rows).map_err(|e| match e {
        Error::InvalidArgument { parameter, message } if parameter == "--window" => Error::invalid(
            "--window",
            format!("{message} (the exemplar is {}×{})", exemplar.columns, exemplar.rows),
        ),
        e => e,
    })?;
    let n = params.window;
    if columns < n || rows < n || columns > MAX_SIDE || rows > MAX_SIDE {
        return Err(Error::invalid(
            "--size",
            format!("{columns}×{rows}: each side must be in {n}..={MAX_SIDE} (at least the window)"),
        ));
    }
    Ok(())
}

/// Prepares growing a new `columns`×`rows` field from `exemplar` (module
/// docs); grow it with [`Growth::grow`] and a search holding
/// [`Growth::exemplar`] and [`Growth::search_config`].
pub fn plan_free_growth(exemplar: &HeightField, columns: u32, rows: u32, params: &FillParams) -> Result<Growth> {
    check_free_growth(exemplar, columns, rows, params)?;
    let (w, n) = (exemplar.columns, params.window);
    let none = vec![false; exemplar.heights.len()];
    let slopes = slopes(exemplar, &none);
    let norm = Normalisation::of(exemplar, &none, &slopes);
    let exemplar_texels = texels(exemplar, &none, &slopes, &norm);
    let inside = Exemplar::inside_centres(w, exemplar.rows, n);
    let mut rng = SplitMix64(u64::from(params.seed) ^ 0x5eed_f4ee);
    let seed_centre = inside[(rng.next_f64() * inside.len() as f64) as usize % inside.len()];
    let ranked = inside.iter().map(|&c| (0, c)).collect();
    let search_exemplar = Exemplar {
        width: w,
        height: exemplar.rows,
        texels: exemplar_texels.clone(),
        candidates: nearest_candidates(ranked, params.candidates, params.seed),
    };
    // The state: unknown everywhere but the seed window at the centre.
    let samples = columns as usize * rows as usize;
    let mut unknown = vec![true; samples];
    let mut state_texels = vec![[0.0f32; 3]; samples];
    let mut state = HeightField {
        columns,
        rows,
        spacing: exemplar.spacing,
        heights: vec![0.0; samples],
    };
    let r = n / 2;
    let (sx, sy) = (seed_centre % w - r, seed_centre / w - r);
    let (ox, oy) = (columns / 2 - r, rows / 2 - r);
    for dy in 0..n {
        for dx in 0..n {
            let from = ((sy + dy) * w + sx + dx) as usize;
            let to = ((oy + dy) * columns + ox + dx) as usize;
            unknown[to] = false;
            state_texels[to] = exemplar_texels[from];
            state.heights[to] = exemplar.heights[from];
        }
    }
    let heights = exemplar.heights.clone();
    let growth = Growth::new(state, unknown, state_texels, search_exemplar, heights, *params)?;
    Ok(growth.paste_with_offset(norm.height_scale as f32))
}

/// [`plan_free_growth`] grown with the CPU search.
pub fn grow_free_cpu(
    exemplar: &HeightField,
    columns: u32,
    rows: u32,
    params: &FillParams,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<HeightField> {
    plan_free_growth(exemplar, columns, rows, params)?.grow_cpu(progress)
}
