//! A fixed-seed test volume for the planner's passes: values in [−1, 1]
//! from a xorshift generator, with every `zero_every`-th voxel zero (the
//! passes skip zeros).

use crate::volume::Volume;

pub(super) fn random(dims: [usize; 3], zero_every: usize) -> Volume {
    let mut state = 0x2545_f491_u32;
    let data: Vec<f32> = (0..dims.iter().product::<usize>())
        .map(|i| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            if i % zero_every == 0 {
                0.0
            } else {
                (state % 2001) as f32 / 1000.0 - 1.0
            }
        })
        .collect();
    Volume::new(dims, data)
}
