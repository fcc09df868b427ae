//! What preprocessing reads: a volume as a source of voxels.

use crate::error::{mismatch, Error, Result};

/// A read-only source of voxels for preprocessing.
pub trait VoxelSource {
    /// Sizes `[nx, ny, nz]`.
    fn dims(&self) -> [usize; 3];
    /// Value of voxel `(i, j, k)`; indices are within `dims`.
    fn voxel(&self, i: usize, j: usize, k: usize) -> f64;

    /// [`VoxelSource::voxel`], refusing NaN and infinities.
    ///
    /// # Errors
    /// [`Error::NonFiniteVoxel`], naming the voxel.
    #[inline]
    fn finite_voxel(&self, i: usize, j: usize, k: usize) -> Result<f64> {
        let v = self.voxel(i, j, k);
        if v.is_finite() {
            Ok(v)
        } else {
            Err(Error::NonFiniteVoxel {
                index: [i, j, k],
                value: v,
            })
        }
    }
}

/// A dense volume borrowed from a slice, `i` fastest.
#[derive(Clone, Copy, Debug)]
pub struct DenseVolume<'a, V> {
    dims: [usize; 3],
    data: &'a [V],
}

impl<'a, V: Copy + Into<f64>> DenseVolume<'a, V> {
    /// Wrap `data` of shape `dims`.
    ///
    /// # Errors
    /// `data.len() != nx·ny·nz`, or a zero dimension.
    pub fn new(dims: [usize; 3], data: &'a [V]) -> Result<Self> {
        require_voxels("volume data", dims, data.len())?;
        Ok(Self { dims, data })
    }
}

impl<V: Copy + Into<f64>> VoxelSource for DenseVolume<'_, V> {
    fn dims(&self) -> [usize; 3] {
        self.dims
    }
    #[inline]
    fn voxel(&self, i: usize, j: usize, k: usize) -> f64 {
        self.data[i + self.dims[0] * (j + self.dims[1] * k)].into()
    }
}

/// Side of the padded cube for a volume: the smallest power of two at least
/// `oversample × max(nx, ny, nz)`.
///
/// # Errors
/// A zero dimension, or a size beyond `usize`.
pub fn padded_size(dims: [usize; 3], oversample: u32) -> Result<usize> {
    if dims.contains(&0) {
        return Err(Error::EmptyVolume);
    }
    let largest = dims.iter().copied().max().unwrap_or(1);
    largest
        .checked_mul(oversample as usize)
        .and_then(usize::checked_next_power_of_two)
        .ok_or(Error::VolumeTooLarge { dims, grid: 0 })
}

/// `Ok` if `got` values are exactly the voxels of `dims`.
///
/// # Errors
/// A zero dimension, a count beyond `usize`, or a length mismatch (`what`).
pub(crate) fn require_voxels(what: &'static str, dims: [usize; 3], got: usize) -> Result<()> {
    if dims.contains(&0) {
        return Err(Error::EmptyVolume);
    }
    let count = dims[0]
        .checked_mul(dims[1])
        .and_then(|v| v.checked_mul(dims[2]))
        .ok_or(Error::VolumeTooLarge { dims, grid: 0 })?;
    if got != count {
        return Err(mismatch(what, count, got));
    }
    Ok(())
}
