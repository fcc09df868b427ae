//! The cheapest configuration predicted to meet a target: candidates, their
//! costs, and the choice.

use fvr_core::filter::FilterKind;
use fvr_core::volume::{padded_size, GridOversampling};

use super::{combine, grid_filter, interpolation, Candidate, Prediction, POW2_GRIDS};
use crate::render::filter::KbDesign;
use crate::render::spectrum::{check_memory, Precision};
use crate::volume::Volume;

/// Relative cost of a candidate: time per view first (`n²` slice samples of
/// `W³` taps, then a 2D transform of `2·n²·log₂n` butterflies), memory
/// (`n³` stored coefficients) second.
pub fn cost(candidate: Candidate, dims: [usize; 3]) -> Result<(f64, f64), fvr_core::Error> {
    cost_grid(
        candidate,
        GridOversampling::from_integer(candidate.oversample)?,
        dims,
    )
}

/// The weight of a mixed-radix 2D transform per `n²·log₂n` against the
/// radix-2 one: an allowance for its strided column gathers and radix-3
/// and -5 stages (the extraction's `W³` taps dominate either way).
const MIXED_TRANSFORM_FACTOR: f64 = 2.0;

/// [`cost`] on the grid `grid`: the side [`GridOversampling::side`], the
/// 2D transform weighted by [`MIXED_TRANSFORM_FACTOR`] on mixed-radix sides.
///
/// # Errors
/// As [`GridOversampling::side`].
pub fn cost_grid(
    candidate: Candidate,
    grid: GridOversampling,
    dims: [usize; 3],
) -> Result<(f64, f64), fvr_core::Error> {
    let side = grid.side(dims)?;
    let n = side as f64;
    let w = candidate.filter.width() as f64;
    let radix = if side.is_power_of_two() {
        1.0
    } else {
        MIXED_TRANSFORM_FACTOR
    };
    let time = n * n * (w * w * w + 2.0 * radix * n.log2());
    Ok((time, n * n * n * candidate.precision.bytes() as f64))
}

/// Filters the planner considers, cheapest first.
pub const CANDIDATE_FILTERS: [FilterKind; 5] = [
    FilterKind::Cubic,
    FilterKind::Kb3,
    FilterKind::Kb4,
    FilterKind::Kb5,
    FilterKind::Kb6,
];

/// Settings fixed by the user: the planner chooses only among candidates
/// that agree with them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Constraints {
    /// A filter given explicitly.
    pub filter: Option<FilterKind>,
    /// An oversampling given explicitly.
    pub oversample: Option<u32>,
    /// A precision given explicitly.
    pub precision: Option<Precision>,
}

/// The planner's choice for a target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plan {
    /// The target, dB.
    pub target_db: f64,
    /// The chosen configuration and its prediction.
    pub prediction: Prediction,
    /// Whether the prediction meets the target (otherwise the candidate
    /// with the best prediction was chosen).
    pub met: bool,
}

/// The cheapest candidate ([`cost`]) predicted to reach `target_db`, among
/// [`CANDIDATE_FILTERS`] × oversampling 1, 2 × f16, f32 restricted by
/// `constraints`; if none does, the best predicted. Candidates whose grid
/// would not fit in memory or be too thin are skipped.
///
/// # Errors
/// As [`predict`]; also no candidate at all fits in memory.
pub fn choose(
    volume: &Volume,
    design: KbDesign,
    target_db: f64,
    constraints: Constraints,
) -> Result<Plan, fvr_core::Error> {
    choose_among(volume, design, target_db, constraints, &POW2_GRIDS)
}

/// [`choose`] among the grids `grids` ([`ALL_GRIDS`] adds the mixed-radix
/// σ = 1.25 and 1.5, costed by [`cost_grid`]); a constraint on the
/// oversampling keeps the grids of that integer oversampling (1: σ = 1,
/// 1.25, 1.5; 2: σ = 2). The chosen grid is [`Prediction::grid`].
///
/// # Errors
/// As [`choose`].
pub fn choose_among(
    volume: &Volume,
    design: KbDesign,
    target_db: f64,
    constraints: Constraints,
    grids: &[GridOversampling],
) -> Result<Plan, fvr_core::Error> {
    let filters: Vec<FilterKind> = match constraints.filter {
        Some(f) => vec![f],
        None => CANDIDATE_FILTERS.to_vec(),
    };
    let grids: Vec<GridOversampling> = grids
        .iter()
        .copied()
        .filter(|g| constraints.oversample.is_none_or(|o| o == g.integer()))
        .collect();
    let precisions: Vec<Precision> = constraints
        .precision
        .map_or(vec![Precision::F16, Precision::F32], |p| vec![p]);
    let mut jobs = Vec::new();
    for &grid in &grids {
        let n = grid.side(volume.dims)?;
        if crate::volume::check_padding(volume.dims, n).is_err() {
            continue;
        }
        let fits: Vec<Precision> = precisions
            .iter()
            .copied()
            .filter(|p| check_memory(n, p.bytes()).is_ok())
            .collect();
        if !fits.is_empty() {
            jobs.extend(filters.iter().map(|&kind| (kind, grid, n, fits.clone())));
        }
    }
    // One pass over the volume per filter and oversampling, on their own threads.
    let results: Vec<Result<Vec<Prediction>, fvr_core::Error>> = std::thread::scope(|scope| {
        let handles: Vec<_> = jobs
            .iter()
            .map(|(kind, grid, n, fits)| {
                scope.spawn(move || {
                    let filter = grid_filter(volume, *kind, *grid, design)?;
                    let interp = interpolation(volume, &filter, *n)?;
                    Ok(fits
                        .iter()
                        .map(|&precision| {
                            let candidate = Candidate {
                                filter: *kind,
                                oversample: grid.integer(),
                                precision,
                            };
                            combine(&interp, candidate, *grid, filter.beta())
                        })
                        .collect())
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a prediction thread panicked"))
            .collect()
    });
    let mut predictions = Vec::new();
    for r in results {
        predictions.extend(r?);
    }
    let costs: Vec<(f64, f64)> = predictions
        .iter()
        .map(|p| cost_grid(p.candidate, p.grid, volume.dims))
        .collect::<Result<_, _>>()?;
    let cheapest_meeting = predictions
        .iter()
        .zip(&costs)
        .filter(|(p, _)| p.db >= target_db)
        .min_by(|a, b| a.1.partial_cmp(b.1).unwrap_or(std::cmp::Ordering::Equal));
    if let Some((p, _)) = cheapest_meeting {
        return Ok(Plan {
            target_db,
            prediction: *p,
            met: true,
        });
    }
    let best = predictions
        .iter()
        .max_by(|a, b| a.db.total_cmp(&b.db))
        .ok_or(fvr_core::Error::VolumeTooLarge {
            dims: volume.dims,
            grid: padded_size(volume.dims, 1)?,
        })?;
    Ok(Plan {
        target_db,
        prediction: *best,
        met: false,
    })
}
