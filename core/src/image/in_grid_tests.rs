//! The image cut into its grid against the one cut into a buffer of its
//! own ([`super::super::finish_with`]): bit for bit, for radix-2 and
//! mixed-radix sides, every kind of placement (negative, beyond `m`,
//! rows that map to themselves) and images narrower or shorter than `m`.

extern crate std;

use std::vec;
use std::vec::Vec;

use super::finish_in_grid;
use crate::dht::{mixed_table_len, MixedPlan, Twiddles};
use crate::image::{aux_len, finish_with, Crop, Inverse, Placement};

/// A fixed-seed pseudo-random grid in `[-1, 1)` (64-bit LCG).
fn grid(m: usize, seed: u64) -> Vec<f32> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..m * m)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        })
        .collect()
}

fn placements() -> [Placement; 5] {
    [
        Placement {
            col0: -32,
            row0: 32,
            shift: [0.0, 0.0],
        },
        Placement {
            col0: -13,
            row0: 7,
            shift: [0.25, 0.5],
        },
        Placement {
            col0: 5,
            row0: -3,
            shift: [0.75, 0.125],
        },
        Placement {
            col0: 70,
            row0: 131,
            shift: [0.0, 0.5],
        },
        Placement {
            col0: 0,
            row0: 0,
            shift: [0.5, 0.0],
        },
    ]
}

/// Both finishes of one grid; panics on any difference.
fn compare(m: usize, inverse: Inverse<'_, f32>, sizes: &[(usize, usize)]) {
    let mut checked = 0;
    for (seed, place) in placements().into_iter().enumerate() {
        for &(width, height) in sizes {
            let crop = Crop::new(place, 0.37, width, height);
            let mut apart = grid(m, seed as u64);
            let mut inside = apart.clone();
            let mut out = vec![f32::NAN; width * height];
            let mut aux = vec![0.0f32; aux_len(m)];
            finish_with(&mut apart, m, &crop, inverse, &mut aux, &mut out).unwrap();
            finish_in_grid(&mut inside, m, &crop, inverse, &mut aux).unwrap();
            let image: Vec<u32> = inside[..width * height]
                .iter()
                .map(|v| v.to_bits())
                .collect();
            let expected: Vec<u32> = out.iter().map(|v| v.to_bits()).collect();
            assert_eq!(image, expected, "m {m}, {place:?}, {width}x{height}");
            assert!(
                out.iter().any(|&v| v != 0.0),
                "an all-zero image checks nothing"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, placements().len() * sizes.len());
}

#[test]
fn radix_2_images_equal_the_ones_cut_apart() {
    const M: usize = 16;
    let mut buf = vec![0.0f32; Twiddles::<f32>::buffer_len(M)];
    let tw = Twiddles::new(&mut buf, M).unwrap();
    compare(
        M,
        Inverse::Radix2(&tw),
        &[(16, 16), (16, 9), (5, 16), (7, 3), (1, 1)],
    );
}

#[test]
fn mixed_radix_images_equal_the_ones_cut_apart() {
    const M: usize = 12;
    let mut buf = vec![0.0f32; mixed_table_len(M)];
    let plan = MixedPlan::new(&mut buf, M).unwrap();
    compare(
        M,
        Inverse::Mixed(&plan),
        &[(12, 12), (12, 5), (4, 12), (11, 7)],
    );
}

#[test]
fn several_channels_are_refused() {
    const M: usize = 8;
    let mut buf = vec![0.0f32; Twiddles::<f32>::buffer_len(M)];
    let tw = Twiddles::new(&mut buf, M).unwrap();
    let mut crop = Crop::new(placements()[0], 1.0, M, M);
    crop.channels = 2;
    let mut g = grid(M, 1);
    let mut aux = vec![0.0f32; aux_len(M)];
    assert!(finish_in_grid(&mut g, M, &crop, Inverse::Radix2(&tw), &mut aux).is_err());
}
