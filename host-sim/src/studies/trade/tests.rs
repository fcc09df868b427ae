//! Unit tests of the sweep's parsing, fronts and outputs.

use super::*;
use crate::studies::precision::StoredSpectrum;
use fvr_core::dht::Rounding;
use fvr_core::filter::Filter;
use fvr_core::geometry::View;
use fvr_core::num::Q15;
use fvr_core::volume::padded_size;
use fvr_engine::volume::phantom::SplitMix64;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use half::f16;

/// On a random cloud with ties, no front point is dominated by any
/// point, and every point off the front is dominated by one on it.
#[test]
fn pareto_front_is_undominated_and_dominates_the_rest() {
    let mut rng = SplitMix64::new(7);
    for trial in 0..20 {
        let count = 1 + trial * 7;
        let mut pts: Vec<(f64, f64)> = (0..count)
            .map(|_| {
                // Coarse values so that ties in ms and in dB occur.
                let ms = (rng.next_f64() * 20.0).round() / 2.0 + 0.1;
                let db = (rng.next_f64() * 12.0).round() * 10.0;
                (ms, db)
            })
            .collect();
        pts.push((f64::NAN, 500.0));
        pts.push((0.01, f64::NAN));
        let front = pareto_front(&pts);
        assert!(
            !front[count] && !front[count + 1],
            "non-finite points are off"
        );
        assert!(front.iter().any(|&f| f), "a finite cloud has a front");
        for (i, &p) in pts.iter().enumerate() {
            if front[i] {
                assert!(
                    pts.iter()
                        .filter(|q| q.0.is_finite() && q.1.is_finite())
                        .all(|&q| !dominates(q, p)),
                    "front point {p:?} is dominated"
                );
            } else if p.0.is_finite() && p.1.is_finite() {
                assert!(
                    pts.iter()
                        .zip(&front)
                        .any(|(&q, &on)| on && dominates(q, p)),
                    "{p:?} is off the front but no front point dominates it"
                );
            }
        }
    }
}

/// A hand-made set: the staircase (1, 10), (2, 30), (4, 50) is the
/// front; (2, 10), (3, 30), (5, 50) and a duplicate-ms slower point are
/// dominated; an exact duplicate of a front point stays on it.
#[test]
fn pareto_front_of_a_known_staircase() {
    let pts = [
        (1.0, 10.0),
        (2.0, 30.0),
        (4.0, 50.0),
        (2.0, 10.0),
        (3.0, 30.0),
        (5.0, 50.0),
        (4.0, 49.0),
        (4.0, 50.0),
    ];
    assert_eq!(
        pareto_front(&pts),
        [true, true, true, false, false, false, false, true]
    );
}

/// The computed spectrum bytes equal what the pipeline allocates, for
/// an element format and a block format.
#[test]
fn memory_model_matches_the_allocated_spectrum() {
    let size = 24;
    let volume = sample(&GaussianMixture::random(1, size, 4), [size; 3]);
    for (format, os) in [
        (Format::F16, 1),
        (Format::Q15(Blocking::Blocks(BlockLayout::Line)), 2),
    ] {
        let st = Setting {
            size,
            filter: FilterKind::Kb3,
            oversample: os,
            format,
            adaptive_db: None,
            level: 0,
        };
        let filter = Filter::new(FilterKind::Kb3, os).unwrap();
        let bytes = match format {
            Format::F16 => {
                StoredSpectrum::<f16>::prepare::<f32>(&volume, filter, Rounding::PerPass)
                    .unwrap()
                    .bytes()
            }
            _ => StoredSpectrum::<Q15>::prepare_in_place::<f32>(
                &volume,
                filter,
                Rounding::PerPass,
                true,
            )
            .unwrap()
            .bytes(),
        };
        assert_eq!(st.memory().spectrum, bytes as u64, "{format:?}");
        assert_eq!(st.grid(), padded_size([size; 3], os).unwrap());
    }
}

/// At pitch 1 the exact reference is [`crate::reference::exact_projection`];
/// at pitch 2 it is every other pixel of the full image.
#[test]
fn exact_at_pitch_subsamples_the_full_image() {
    let n = 32;
    let p = GaussianMixture::random(3, n, 4);
    let v = View::along(view_directions(2)[1]);
    let full = crate::reference::exact_projection(&p, [n; 3], &v, n, n).unwrap();
    // Same positions up to the rounding of c + 1·(p − c).
    let peak = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let same = exact_at_pitch(&p, [n; 3], &v, n, n, 1.0).unwrap();
    let worst = same
        .iter()
        .zip(&full)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst <= 1e-12 * peak, "pitch 1 differs by {worst}");
    let half = exact_at_pitch(&p, [n; 3], &v, n / 2, n / 2, 2.0).unwrap();
    for row in 0..n / 2 {
        for col in 0..n / 2 {
            let (a, b) = (half[row * n / 2 + col], full[2 * row * n + 2 * col]);
            assert!(
                (a - b).abs() <= 1e-12 * peak,
                "{row},{col}: {a} against {b}"
            );
        }
    }
}

#[test]
fn byte_counts_parse_with_suffixes() {
    let parse_bytes = |s| crate::budget::parse_bytes("--memory-limit", s);
    assert_eq!(parse_bytes("1024").unwrap(), 1024);
    assert_eq!(parse_bytes("3K").unwrap(), 3072);
    assert_eq!(parse_bytes("2M").unwrap(), 2 << 20);
    assert_eq!(parse_bytes("1G").unwrap(), 1 << 30);
    assert!(parse_bytes("x").is_err());
    assert!(parse_bytes("99999999999G").is_err());
}

#[test]
fn views_are_never_parallel_to_the_up_hint() {
    for d in view_directions(64) {
        assert!(d[2].abs() < 0.7, "{d:?}");
        assert!(View::along(d).frame().is_ok());
    }
}
