//! The cheapest configuration predicted to meet a target: candidates, their
//! costs, and the choice.

use std::sync::OnceLock;

use fvr_core::filter::{EnergyProfile, Filter, FilterKind};
use fvr_core::volume::{padded_size, DenseVolume, GridOversampling};

use super::model::{combine, grid_filter, interpolation, Candidate, Prediction, POW2_GRIDS};
use crate::plan::filter::KbDesign;
use crate::spectrum::{check_memory, Precision};
use crate::volume::Volume;
use rayon::prelude::*;

/// One pass over the volume: a filter on a grid of side `n` and the
/// precisions that fit in memory.
type Job = (FilterKind, GridOversampling, usize, Vec<Precision>);

/// Relative cost of a candidate: time per view first
/// ([`cost_grid`]), memory (`n³` stored coefficients) second.
pub fn cost(candidate: Candidate, dims: [usize; 3]) -> Result<(f64, f64), fvr_core::Error> {
    cost_grid(
        candidate,
        GridOversampling::from_integer(candidate.oversample)?,
        dims,
    )
}

/// CPU ms of one view on one thread with a grid of side 256, by filter:
/// the fit of `cargo bench -p fvr-host --bench plan_cost` on the CT head
/// (f16; views of `image_side` pixels over an orbit). Even widths cost
/// more per tap than odd ones (kb4 as much as cubic, 2.2× kb3), so the
/// weights are measured rather than `W³`. Nearest and linear, never
/// candidates, are kb3's weight scaled by their taps.
fn view_weight(kind: FilterKind) -> f64 {
    match kind {
        FilterKind::Nearest => 2.85 / 27.0,
        FilterKind::Linear => 2.85 * 8.0 / 27.0,
        FilterKind::Kb3 => 2.85,
        FilterKind::Cubic | FilterKind::Kb4 => 6.3,
        FilterKind::Kb5 => 7.6,
        FilterKind::Kb6 => 10.9,
    }
}

/// How the time per view grows with the grid side `n` (`n^2.1`: the
/// slice's `n²` samples, their taps missing the cache more on larger
/// spectra, and the `n² log n` 2D transform), and the factor of a
/// mixed-radix side over a power of two at the same `n`; both fitted with
/// [`view_weight`].
const SIDE_EXPONENT: f64 = 2.1;
const MIXED_FACTOR: f64 = 1.28;

/// [`cost`] on the grid `grid`: time per view `w·(n/256)^2.1`, times
/// 1.28 on mixed-radix sides (`w` from a measured table of the filters),
/// then memory.
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
    let mixed = if side.is_power_of_two() {
        1.0
    } else {
        MIXED_FACTOR
    };
    let time = view_weight(candidate.filter) * (n / 256.0).powf(SIDE_EXPONENT) * mixed;
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
    /// A grid oversampling given explicitly.
    pub oversample: Option<GridOversampling>,
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

/// The planner prefers configurations predicted at least this far above
/// the target: the bound the tests hold every prediction to (never more
/// than 3 dB optimistic on the worst view), so that the measured SNR
/// reaches the target.
pub const MARGIN_DB: f64 = 3.0;

/// What the bound on a job passed by ([`choose_among`]) allows for the
/// rounding of `combine`'s few operations, dB.
const BOUND_SLACK_DB: f64 = 1e-9;

/// The cheapest candidate ([`cost`]) predicted to reach `target_db` +
/// [`MARGIN_DB`] (or, if none does, `target_db`), among
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
/// oversampling keeps that grid only, whether or not `grids` lists it.
/// The chosen grid is [`Prediction::grid`].
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
    walk(volume, design, target_db, constraints, grids, true)
}

/// [`choose_among`]; `from_volume` lets the volume show positive signal
/// ([`signal_on_every_view`]) before any job has run (false: only a job
/// run shows it).
fn walk(
    volume: &Volume,
    design: KbDesign,
    target_db: f64,
    constraints: Constraints,
    grids: &[GridOversampling],
    from_volume: bool,
) -> Result<Plan, fvr_core::Error> {
    let filters: Vec<FilterKind> = match constraints.filter {
        Some(f) => vec![f],
        None => CANDIDATE_FILTERS.to_vec(),
    };
    let grids: Vec<GridOversampling> = match constraints.oversample {
        Some(g) => vec![g],
        None => grids.to_vec(),
    };
    let precisions: Vec<Precision> = constraints
        .precision
        .map_or(vec![Precision::F16, Precision::F32], |p| vec![p]);
    let shadows = super::wrap::Shadows::new(volume);
    let mut jobs: Vec<Job> = Vec::new();
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
    // Candidates in order of cost (stable: ties keep the order above, as
    // `min_by` would), each job's pass over the volume run only when the
    // walk reaches one of its candidates: the first predicted to reach the
    // target with the margin is the cheapest that does, so the jobs of
    // costlier candidates are never run. Jobs run a batch at a time, one
    // per thread, the next ones in cost order.
    let mut order = Vec::new();
    for (j, (kind, grid, _, fits)) in jobs.iter().enumerate() {
        for (f, &precision) in fits.iter().enumerate() {
            let candidate = Candidate {
                filter: *kind,
                oversample: grid.integer(),
                precision,
            };
            order.push((j, f, cost_grid(candidate, *grid, volume.dims)?));
        }
    }
    order.sort_by(|a, b| a.2.partial_cmp(&b.2).unwrap_or(std::cmp::Ordering::Equal));
    // The energy profile a Kaiser–Bessel design is fitted to, once per
    // grid side for all the kinds fitted on it.
    let source = DenseVolume::new(volume.dims, &volume.data)?;
    let mut sides: Vec<usize> = jobs.iter().map(|j| j.2).collect();
    sides.dedup();
    let profiles: Vec<(usize, OnceLock<Result<EnergyProfile, fvr_core::Error>>)> =
        sides.into_iter().map(|n| (n, OnceLock::new())).collect();
    // The wrapped-shadow ratio of each grid side, made when the walk first
    // reaches one of its jobs.
    let mut wraps: Vec<(usize, f64)> = Vec::new();
    let run = |(kind, grid, n, fits): &Job,
               wraps: &[(usize, f64)]|
     -> Result<Vec<Prediction>, fvr_core::Error> {
        let wrap = wraps.iter().find(|(m, _)| m == n).map_or(0.0, |&(_, w)| w);
        let filter = match profiles.iter().find(|(m, _)| m == n) {
            Some((_, profile)) if design == KbDesign::Auto && kind.is_kaiser_bessel() => {
                let profile = profile.get_or_init(|| EnergyProfile::of(&source, *n));
                Filter::fit_grid_profile(*kind, *grid, profile.as_ref().map_err(|e| *e)?)?.0
            }
            _ => grid_filter(volume, *kind, *grid, design)?,
        };
        let interp = interpolation(volume, &filter, *n)?;
        Ok(fits
            .iter()
            .map(|&precision| {
                let candidate = Candidate {
                    filter: *kind,
                    oversample: grid.integer(),
                    precision,
                };
                combine(&interp, candidate, *grid, filter.beta(), wrap)
            })
            .collect())
    };
    let batch = rayon::current_num_threads().max(1);
    let mut done: Vec<Option<Vec<Prediction>>> = vec![None; jobs.len()];
    let wrap_of = |n: usize, wraps: &mut Vec<(usize, f64)>| -> Result<f64, fvr_core::Error> {
        if let Some(&(_, w)) = wraps.iter().find(|&&(m, _)| m == n) {
            return Ok(w);
        }
        let w = shadows.worst_ratio(n, super::model::image_side(volume.dims, n)?);
        wraps.push((n, w));
        Ok(w)
    };
    // A job is not run while the walk can pass it by: its wrap term alone
    // keeps every candidate below the target with the margin. `combine`
    // adds `wrap·Σs²` to the worst axis view's error, so the SNR is at most
    // `−10·log₁₀ wrap` once that view's `Σs²` is positive. `Σs²`, the
    // energy of the voxel sums in the image, is the same for every job (to
    // the order of its additions): a job already run with a finite SNR on
    // every view shows it; so does the volume itself when every job's
    // image side is even and [`signal_on_every_view`] holds, before any
    // job has run.
    let even = jobs
        .iter()
        .all(|j| super::model::image_side(volume.dims, j.2).is_ok_and(|side| side % 2 == 0));
    let mut positive = from_volume && even && signal_on_every_view(volume);
    let hopeless = |wrap: f64, positive: bool| {
        positive && wrap > 0.0 && -10.0 * wrap.log10() + BOUND_SLACK_DB < target_db + MARGIN_DB
    };
    for (at, &(j, f, _)) in order.iter().enumerate() {
        if done[j].is_none() {
            if hopeless(wrap_of(jobs[j].2, &mut wraps)?, positive) {
                continue;
            }
            let mut next: Vec<usize> = Vec::with_capacity(batch);
            for &(k, _, _) in &order[at..] {
                if done[k].is_none()
                    && !next.contains(&k)
                    && !hopeless(wrap_of(jobs[k].2, &mut wraps)?, positive)
                {
                    next.push(k);
                    if next.len() == batch {
                        break;
                    }
                }
            }
            let results: Vec<_> = next.par_iter().map(|&k| run(&jobs[k], &wraps)).collect();
            for (k, r) in next.into_iter().zip(results) {
                let r = r?;
                positive |= r.iter().any(|p| p.views_db.iter().all(|d| d.is_finite()));
                done[k] = Some(r);
            }
        }
        let p = done[j].as_ref().map(|d| d[f]);
        if let Some(p) = p.filter(|p| p.db >= target_db + MARGIN_DB) {
            return Ok(Plan {
                target_db,
                prediction: p,
                met: true,
            });
        }
    }
    // None reaches the margin: the jobs passed by run now, so that every
    // job has run.
    let rest: Vec<usize> = (0..jobs.len()).filter(|&k| done[k].is_none()).collect();
    for &k in &rest {
        wrap_of(jobs[k].2, &mut wraps)?;
    }
    let results: Vec<_> = rest.par_iter().map(|&k| run(&jobs[k], &wraps)).collect();
    for (k, r) in rest.into_iter().zip(results) {
        done[k] = Some(r?);
    }
    let predictions: Vec<Prediction> = order
        .iter()
        .filter_map(|&(j, f, _)| done[j].as_ref().map(|d| d[f]))
        .collect();
    if let Some(p) = predictions.iter().find(|p| p.db >= target_db) {
        return Ok(Plan {
            target_db,
            prediction: *p,
            met: true,
        });
    }
    // The best in the order of the jobs (`max_by` keeps the last of equals).
    let best = done
        .iter()
        .flatten()
        .flatten()
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

/// Whether every axis view's reference image is sure to have positive
/// energy `Σs²` on any grid: every voxel is finite, and each axis's
/// central line (the other two coordinates at `⌊dims/2⌋`) sums to a value
/// no order of additions can round to zero. The view along that axis
/// images the line at the image's centre pixel, inside the volume on any
/// grid whose image side is even, and its reference there is the line's
/// sum, added in some order: with `m` voxels `|fl(Σf) − Σf| ≤ γ_m·Σ|f|`
/// (`γ_m ≈ m·u`) whatever the order, so a sum that exceeds twice that
/// bound (this function's own rounding included) is non-zero in every
/// order, and so is the view's `Σs²`. A non-negative volume with a
/// positive voxel on each line always passes; a signed one (CT in
/// Hounsfield units) passes unless a line cancels.
fn signal_on_every_view(volume: &Volume) -> bool {
    let [d0, d1, d2] = volume.dims;
    if volume.first_non_finite().is_some() {
        return false;
    }
    let (c0, c1, c2) = (d0 / 2, d1 / 2, d2 / 2);
    let at = |i: usize, j: usize, k: usize| f64::from(volume.data[(k * d1 + j) * d0 + i]);
    let certain = |line: &mut dyn Iterator<Item = f64>| {
        let (mut sum, mut mass, mut m) = (0.0f64, 0.0f64, 0usize);
        for v in line {
            sum += v;
            mass += v.abs();
            m += 1;
        }
        sum.abs() > 2.0 * (m + 1) as f64 * f64::EPSILON * mass
    };
    certain(&mut (0..d0).map(|i| at(i, c1, c2)))
        && certain(&mut (0..d1).map(|j| at(c0, j, c2)))
        && certain(&mut (0..d2).map(|k| at(c0, c1, k)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bits of a plan's prediction.
    fn bits(plan: &Plan) -> Vec<u64> {
        let p = plan.prediction;
        [p.db, p.beta]
            .into_iter()
            .chain(p.views_db)
            .chain(p.parts_db)
            .map(f64::to_bits)
            .collect()
    }

    /// A test volume with the planner's shadows: non-negative (|v|), or
    /// signed.
    fn volume(non_negative: bool) -> Volume {
        let mut v = crate::plan::test_volume::random([24, 20, 14], 5);
        if non_negative {
            v.data.iter_mut().for_each(|x| *x = x.abs());
        }
        v
    }

    #[test]
    fn jobs_passed_by_before_any_has_run_change_no_choice() {
        let mut met = 0;
        for non_negative in [true, false] {
            let v = volume(non_negative);
            // Signed or not, the random volume's central lines do not cancel.
            assert!(signal_on_every_view(&v));
            for target in [20.0, 35.0, 50.0, 65.0, 90.0] {
                let constraints = Constraints::default();
                let grids = &crate::plan::ALL_GRIDS;
                let with =
                    walk(&v, KbDesign::Auto, target, constraints, grids, true).expect("plan");
                let without =
                    walk(&v, KbDesign::Auto, target, constraints, grids, false).expect("plan");
                assert_eq!(with, without, "target {target}");
                assert_eq!(bits(&with), bits(&without), "target {target}");
                met += usize::from(with.met);
            }
        }
        // Not vacuous: some targets met.
        assert!(met > 0);
    }

    #[test]
    fn the_plan_is_the_same_bits_on_one_thread_and_on_four() {
        for non_negative in [true, false] {
            let v = volume(non_negative);
            for target in [35.0, 65.0] {
                let plan = |threads: usize| {
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(threads)
                        .build()
                        .expect("pool")
                        .install(|| {
                            let all = &crate::plan::ALL_GRIDS;
                            choose_among(&v, KbDesign::Auto, target, Constraints::default(), all)
                        })
                        .expect("plan")
                };
                let (one, four) = (plan(1), plan(4));
                assert_eq!(one, four, "target {target}");
                assert_eq!(bits(&one), bits(&four), "target {target}");
            }
        }
    }

    #[test]
    fn the_signal_test_needs_each_central_line_to_sum_to_a_certain_non_zero() {
        let dims = [5, 4, 3];
        let len = 5 * 4 * 3;
        let index = |i: usize, j: usize, k: usize| (k * 4 + j) * 5 + i;
        // Only the centre voxel (2, 2, 1) lies on all three central lines.
        let mut data = vec![0.0f32; len];
        data[index(2, 2, 1)] = 1.0;
        assert!(signal_on_every_view(&Volume::new(dims, data.clone())));
        // Negative works as well as positive (CT in Hounsfield units).
        data[index(2, 2, 1)] = -1024.0;
        assert!(signal_on_every_view(&Volume::new(dims, data.clone())));
        // Off the central line of x and z (on y's): not sure.
        let mut off = vec![0.0f32; len];
        off[index(2, 0, 1)] = 1.0;
        assert!(!signal_on_every_view(&Volume::new(dims, off)));
        // One line per axis, each through another voxel: sure.
        let mut lines = vec![0.0f32; len];
        for at in [index(0, 2, 1), index(2, 3, 1), index(2, 2, 0)] {
            lines[at] = 1.0;
        }
        assert!(signal_on_every_view(&Volume::new(dims, lines)));
        // A line that cancels exactly, or to within its rounding, is not
        // sure; values elsewhere change nothing.
        // x's central line: (j, k) = (2, 1). 3e38 − 3e38 + 1e-30 is not
        // zero, but adding 3e38 first rounds it to zero.
        for (line, sure) in [
            ([3.0f32, -3.0, 0.0], false),
            ([3.0e38, -3.0e38, 1.0e-30], false),
            ([3.0, -2.0, 0.0], true),
        ] {
            let mut d = data.clone();
            for (i, v) in line.into_iter().enumerate() {
                d[index(i, 2, 1)] = v;
            }
            d[index(2, 3, 1)] = 1.0;
            d[index(2, 2, 0)] = 1.0;
            assert_eq!(
                signal_on_every_view(&Volume::new(dims, d.clone())),
                sure,
                "{line:?}"
            );
            d[index(4, 0, 0)] = -7.0;
            assert_eq!(
                signal_on_every_view(&Volume::new(dims, d)),
                sure,
                "{line:?}"
            );
        }
        // A non-finite voxel anywhere is for the jobs to report.
        for bad in [f32::INFINITY, f32::NAN] {
            let mut d = data.clone();
            d[index(4, 0, 0)] = bad;
            assert!(!signal_on_every_view(&Volume::new(dims, d)), "{bad}");
        }
        assert!(!signal_on_every_view(&Volume::new(dims, vec![0.0; len])));
    }
}
