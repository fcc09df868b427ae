//! An owned 3D volume of f32 samples, the host-side input to the core.

/// A dense 3D volume. Voxel `(i, j, k)` is stored at `i + nx * (j + ny * k)`:
/// `i` is the fastest axis, as in NRRD and raw files.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Sizes `[nx, ny, nz]`.
    pub dims: [usize; 3],
    /// Samples, `nx * ny * nz` of them, `i` fastest.
    pub data: Vec<f32>,
}

impl Volume {
    /// A volume of zeros.
    pub fn zeros(dims: [usize; 3]) -> Self {
        Self {
            dims,
            data: vec![0.0; dims[0] * dims[1] * dims[2]],
        }
    }

    /// Linear index of voxel `(i, j, k)`.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Sample at voxel `(i, j, k)`.
    #[inline]
    pub fn get(&self, i: usize, j: usize, k: usize) -> f32 {
        self.data[self.index(i, j, k)]
    }
}
