//! The threaded finish (`render::fast_inverse`) against the core's
//! `finish_with`, the reference: the same image bit for bit on mixed-radix
//! and power-of-two sides, in f32 and f64, for shifted and unshifted
//! placements, crops that wrap, interleaved channels and any thread count;
//! odd sides, which the core's finish does not take, against the core's
//! 2D transform; grids with rows of `+0` and of `−0`.

use fvr_core::dht::{dht_2d_mixed, dht_2d_mixed_scratch_len, mixed_table_len, MixedPlan, Twiddles};
use fvr_core::image::{aux_len, finish_with, Crop, Inverse, Placement};
use fvr_core::num::Real;
use fvr_engine::image::inverse::{finish_threaded, MixedFinish};

/// A fixed-seed pseudo-random grid in [−0.5, 0.5), with the rows of a
/// weak slice: every fourth row from row 2 `+0` (its mirror too, where `m`
/// is even), and row 3 `−0`, which is no `+0` row.
fn grid<T: Real>(m: usize, seed: u32) -> Vec<T> {
    let mut state = seed;
    (0..m * m)
        .map(|i| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            match i / m {
                y if y % 4 == 2 => T::ZERO,
                3 => T::from_f64(-0.0),
                _ => T::from_f64((state >> 8) as f64 / 16_777_216.0 - 0.5),
            }
        })
        .collect()
}

/// Crops of side `m`: the whole grid unshifted, a shifted one that wraps
/// on both axes, a small off-centre one, and channel 1 of three.
fn crops(m: usize) -> Vec<Crop> {
    let place = |col0: i64, row0: i64, shift: [f64; 2]| Placement { col0, row0, shift };
    let mut three = Crop::new(place(-(m as i64) / 3, 5, [0.25, 0.0]), 1.5, m / 2, m / 3);
    three.channels = 3;
    three.channel = 1;
    vec![
        Crop::new(place(0, 0, [0.0, 0.0]), 1.0, m, m),
        Crop::new(place(-(m as i64) / 2, m as i64 / 2, [0.5, 0.5]), 0.75, m, m),
        Crop::new(place(7, -3, [0.1, 0.9]), 2.0, m.div_ceil(3), m / 2),
        three,
    ]
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

/// The core's image and the threaded one on 1, 2 and 3 threads, for
/// every crop, from the same grid.
fn agree<T: Real>(m: usize, inverse: Inverse<'_, T>) {
    let mut lanes = match inverse {
        Inverse::Mixed(_) => Some(MixedFinish::<T>::new(m).unwrap()),
        Inverse::Radix2(_) => None,
    };
    for (i, crop) in crops(m).iter().enumerate() {
        let input = grid::<T>(m, 7 + i as u32);
        let len = crop.width * crop.height * crop.channels;
        let mut want = vec![T::from_f64(-9.0); len];
        let (mut g, mut aux) = (input.clone(), vec![T::ZERO; aux_len(m)]);
        finish_with(&mut g, m, crop, inverse, &mut aux, &mut want).unwrap();
        // The core's image is a transform, not a copy of its input.
        assert_ne!(want[..crop.width], input[..crop.width], "side {m}");
        for threads in [1, 2, 3] {
            let mut got = vec![T::from_f64(-9.0); len];
            let (mut g, mut trans) = (input.clone(), vec![T::ZERO; m * m]);
            pool(threads)
                .install(|| finish_threaded(&mut g, m, crop, inverse, &mut trans, &mut got))
                .unwrap();
            let bits = |v: &[T]| v.iter().map(|x| x.to_f64().to_bits()).collect::<Vec<_>>();
            assert!(
                bits(&got) == bits(&want),
                "side {m}, crop {i}, {threads} threads: differs from the core"
            );
            if let Some(lanes) = lanes.as_mut() {
                let mut got = vec![T::from_f64(-9.0); len];
                let mut g = input.clone();
                pool(threads)
                    .install(|| lanes.finish(&mut g, crop, &mut got))
                    .unwrap();
                assert!(
                    bits(&got) == bits(&want),
                    "side {m}, crop {i}, {threads} threads: lanes differ from the core"
                );
            }
        }
    }
}

fn mixed_sides<T: Real>() {
    for m in [20, 40, 48, 80, 160, 320] {
        let mut table = vec![T::ZERO; mixed_table_len(m)];
        let plan = MixedPlan::new(&mut table, m).unwrap();
        agree(m, Inverse::Mixed(&plan));
    }
}

fn radix2_sides<T: Real>() {
    for m in [4, 16, 64, 256] {
        let mut tw_buf = vec![T::ZERO; Twiddles::<T>::buffer_len(m)];
        let tw = Twiddles::new(&mut tw_buf, m).unwrap();
        agree(m, Inverse::Radix2(&tw));
    }
}

#[test]
fn mixed_sides_match_the_core_in_f32() {
    mixed_sides::<f32>();
}

#[test]
fn mixed_sides_match_the_core_in_f64() {
    mixed_sides::<f64>();
}

#[test]
fn radix2_sides_match_the_core() {
    radix2_sides::<f32>();
    radix2_sides::<f64>();
}

/// Odd sides: the core's finish needs more scratch than `aux_len` gives
/// them, so the reference is its 2D transform, cropped here by the same
/// rule (grid row `row0 − row`, column `col0 + col`, modulo `m`) with no
/// shift.
fn odd_sides<T: Real>() {
    for m in [15, 45, 75, 81, 125] {
        let mut table = vec![T::ZERO; mixed_table_len(m)];
        let plan = MixedPlan::new(&mut table, m).unwrap();
        let input = grid::<T>(m, 99);
        let mut transformed = input.clone();
        let mut scratch = vec![T::ZERO; dht_2d_mixed_scratch_len(m, m)];
        dht_2d_mixed(&mut transformed, m, m, &mut scratch, [&plan, &plan]).unwrap();
        let place = Placement {
            col0: -(m as i64) / 2,
            row0: m as i64 / 2,
            shift: [0.0, 0.0],
        };
        let crop = Crop::new(place, 1.25, m - 2, m);
        let g = T::from_f64(1.25 / (m * m) as f64);
        let modulo = |v: i64| v.rem_euclid(m as i64) as usize;
        let want: Vec<T> = (0..crop.height)
            .flat_map(|row| (0..crop.width).map(move |col| (row, col)))
            .map(|(row, col)| {
                let (gy, gx) = (
                    modulo(place.row0 - row as i64),
                    modulo(place.col0 + col as i64),
                );
                transformed[gy * m + gx] * g
            })
            .collect();
        let mut got = vec![T::ZERO; want.len()];
        let (mut g, mut trans) = (input, vec![T::ZERO; m * m]);
        pool(2)
            .install(|| {
                finish_threaded(
                    &mut g,
                    m,
                    &crop,
                    Inverse::Mixed(&plan),
                    &mut trans,
                    &mut got,
                )
            })
            .unwrap();
        let bits = |v: &[T]| v.iter().map(|x| x.to_f64().to_bits()).collect::<Vec<_>>();
        assert!(bits(&got) == bits(&want), "odd side {m}");
        let mut again = vec![T::ZERO; want.len()];
        let mut g = grid::<T>(m, 99);
        MixedFinish::<T>::new(m)
            .unwrap()
            .finish(&mut g, &crop, &mut again)
            .unwrap();
        assert!(bits(&again) == bits(&want), "odd side {m}, MixedFinish");
    }
}

#[test]
fn odd_sides_match_the_core_transform() {
    odd_sides::<f32>();
    odd_sides::<f64>();
}

#[test]
fn refuses_what_the_core_refuses() {
    let m = 40;
    let mut table = vec![0.0f32; mixed_table_len(48)];
    let plan48 = MixedPlan::new(&mut table, 48).unwrap();
    let crop = Crop::new(
        Placement {
            col0: 0,
            row0: 0,
            shift: [0.0, 0.0],
        },
        1.0,
        m,
        m,
    );
    let (mut g, mut trans, mut out) = (vec![0.0f32; m * m], vec![0.0f32; m * m], vec![0.0; m * m]);
    // A plan for another side.
    assert!(finish_threaded(
        &mut g,
        m,
        &crop,
        Inverse::Mixed(&plan48),
        &mut trans,
        &mut out
    )
    .is_err());
    let mut table = vec![0.0f32; mixed_table_len(m)];
    let plan = MixedPlan::new(&mut table, m).unwrap();
    let inverse = Inverse::Mixed(&plan);
    // Short transposed grid, short image, an image larger than the grid.
    assert!(finish_threaded(&mut g, m, &crop, inverse, &mut trans[1..], &mut out).is_err());
    assert!(finish_threaded(&mut g, m, &crop, inverse, &mut trans, &mut out[1..]).is_err());
    let big = Crop::new(crop.place, 1.0, m + 1, m);
    assert!(finish_threaded(&mut g, m, &big, inverse, &mut trans, &mut out).is_err());
    let mut bad = crop;
    bad.channel = 1;
    assert!(finish_threaded(&mut g, m, &bad, inverse, &mut trans, &mut out).is_err());
    assert!(finish_threaded(&mut g, m, &crop, inverse, &mut trans, &mut out).is_ok());
}
