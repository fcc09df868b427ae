//! The fit from a shared energy profile is the fit from the volume.

use fvr_core::filter::{EnergyProfile, Filter, FilterKind};
use fvr_core::volume::{DenseVolume, GridOversampling};

#[test]
fn a_fit_from_the_profile_is_the_fit_from_the_volume_bit_for_bit() {
    // A compact blob off centre (so that the fit moves off the lowest
    // design) and a box that fills its grid (so that it stays there).
    let dims = [20, 17, 12];
    let blob: Vec<f32> = (0..dims.iter().product::<usize>())
        .map(|i| {
            let (x, y, z) = (i % 20, i / 20 % 17, i / 340);
            let r2 = (x as f32 - 8.0).powi(2) + (y as f32 - 9.0).powi(2) + (z as f32 - 6.0).powi(2);
            (-r2 / 6.0).exp()
        })
        .collect();
    let full = vec![1.0f32; dims.iter().product()];
    let mut designs = Vec::new();
    for voxels in [&blob, &full] {
        let volume = DenseVolume::new(dims, voxels).unwrap();
        for grid in GridOversampling::ALL {
            let n = grid.side(dims).unwrap();
            let profile = EnergyProfile::of(&volume, n).unwrap();
            for kind in [
                FilterKind::Cubic,
                FilterKind::Kb3,
                FilterKind::Kb4,
                FilterKind::Kb6,
            ] {
                let direct = Filter::fit_grid(kind, grid, &volume).unwrap();
                let shared = Filter::fit_grid_profile(kind, grid, &profile).unwrap();
                assert_eq!(direct.0, shared.0, "{kind:?} {grid:?}");
                assert_eq!(direct.1.to_bits(), shared.1.to_bits(), "{kind:?} {grid:?}");
                if grid.is_pow2() {
                    assert_eq!(Filter::fit(kind, grid.integer(), &volume).unwrap(), direct);
                }
                designs.push(direct.1);
            }
        }
    }
    // Not vacuous: some fits left the lowest design.
    assert!(designs.iter().any(|&d| d > 2.0), "{designs:?}");
}
