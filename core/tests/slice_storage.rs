//! One slice whatever the storage: the same Q15 coefficients stored plain,
//! with per-line exponents of zero and with per-brick exponents of zero
//! give the same slice to f64 rounding. The plain and per-line extraction
//! and the general one (bricks, read tap by tap) must walk the same points
//! with the same windows, including the mirrored half of the slice, where
//! an integer position's even-width window is one-sided.

use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::SliceAxes;
use fvr_core::num::{BlockExponents, BlockLayout, Q15};
use fvr_core::slice::extract_central_slice_on;
use fvr_core::spectrum::Spectrum;

/// Fixed-seed Q15 coefficients, `n³`.
fn coefficients(n: usize) -> Vec<Q15> {
    let mut s = 1u32;
    (0..n * n * n)
        .map(|_| {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            Q15((s >> 16) as u16 as i16)
        })
        .collect()
}

/// An orthonormal pair spanning the plane normal to `d`.
fn axes_normal_to(d: [f64; 3]) -> SliceAxes {
    let norm = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / l)
    };
    let d = norm(d);
    let helper = if d[2].abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let right = norm(cross(helper, d));
    SliceAxes {
        right,
        up: cross(d, right),
    }
}

/// The side of a cube of `len` values.
fn side_of(len: usize) -> usize {
    (1..=len).find(|s| s * s * s >= len).unwrap_or(0)
}

fn slice(spec: &Spectrum<'_, Q15>, kernel: &KernelTable<f64>, axes: &SliceAxes) -> Vec<f64> {
    let n = spec.n();
    let mut grid = vec![0.0; n * n];
    extract_central_slice_on(spec, kernel, axes, n, &mut grid);
    grid
}

#[test]
fn every_storage_gives_the_plain_slice() {
    let n = 16;
    let m = coefficients(n);
    let zero_lines = vec![0i8; n * n];
    let zero_bricks4 = vec![0i8; (n / 4) * (n / 4) * (n / 4)];
    let zero_cube = vec![0i8; 1];
    for kind in [
        FilterKind::Kb3,
        FilterKind::Kb4,
        FilterKind::Kb6,
        FilterKind::Cubic,
    ] {
        let f = Filter::new(kind, 1).unwrap();
        let kernel = KernelTable::<f64>::new(f);
        let plain = Spectrum::from_parts(&m, n, 1.0, f, [n; 3]).unwrap();
        fn blocked<'a>(
            m: &'a [Q15],
            layout: BlockLayout,
            e: &'a [i8],
            f: Filter,
        ) -> Spectrum<'a, Q15> {
            let n = side_of(m.len());
            let b = BlockExponents::new(layout, e, n).unwrap();
            Spectrum::from_blocks(m, b, n, 1.0, f, [n; 3]).unwrap()
        }
        let stored = [
            ("per line", blocked(&m, BlockLayout::Line, &zero_lines, f)),
            (
                "per 4³ brick",
                blocked(&m, BlockLayout::Brick(4), &zero_bricks4, f),
            ),
            (
                "one brick",
                blocked(&m, BlockLayout::Brick(n), &zero_cube, f),
            ),
        ];
        // Axis views put every slice point on an integer position along
        // the view axis; the others only some.
        for d in [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.3, 0.2],
            [1.0, 1.0, 1.0],
        ] {
            let axes = axes_normal_to(d);
            let want = slice(&plain, &kernel, &axes);
            let peak = want.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(peak > 0.0);
            for (name, spec) in &stored {
                let got = slice(spec, &kernel, &axes);
                let worst = want
                    .iter()
                    .zip(&got)
                    .fold(0.0f64, |a, (w, g)| a.max((w - g).abs()));
                // Sums of W³ products of f64 in another order: far below 1e-12.
                assert!(
                    worst <= 1e-12 * peak,
                    "{kind:?} {name}, view {d:?}: differs by {worst:e} of a peak of {peak:e}"
                );
            }
        }
    }
}
