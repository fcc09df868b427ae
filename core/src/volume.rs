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

    /// The voxels, `i` fastest.
    pub fn samples(&self) -> &'a [V] {
        self.data
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

/// A grid oversampling factor `σ = q/4` in quarters `q`: 1, 1.25, 1.5 or 2
/// (`q` = 4, 5, 6, 8). Factors 1 and 2 give the power-of-two sides of
/// [`padded_size`]; 1.25 and 1.5 give mixed-radix sides (`2^a·3^b·5^c`,
/// even), which the host prepares and renders with the mixed-radix
/// transforms ([`crate::dht::mixed`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GridOversampling(u8);

impl GridOversampling {
    /// σ = 1: the smallest power of two holding the volume.
    pub const X1: Self = Self(4);
    /// σ = 1.25, mixed radix.
    pub const X1_25: Self = Self(5);
    /// σ = 1.5, mixed radix.
    pub const X1_5: Self = Self(6);
    /// σ = 2: twice the largest side, a power of two.
    pub const X2: Self = Self(8);
    /// Every factor, smallest first.
    pub const ALL: [Self; 4] = [Self::X1, Self::X1_25, Self::X1_5, Self::X2];

    /// The factor of an integer oversampling (1 or 2).
    ///
    /// # Errors
    /// [`Error::UnsupportedOversampling`] for other factors.
    pub fn from_integer(oversample: u32) -> Result<Self> {
        match oversample {
            1 => Ok(Self::X1),
            2 => Ok(Self::X2),
            factor => Err(Error::UnsupportedOversampling { factor }),
        }
    }

    /// Parse `1`, `1.25`, `1.5` or `2`; `None` otherwise.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|g| g.name() == name)
    }

    /// The factor as written on the command line.
    pub const fn name(self) -> &'static str {
        match self.0 {
            4 => "1",
            5 => "1.25",
            6 => "1.5",
            _ => "2",
        }
    }

    /// σ.
    pub fn factor(self) -> f64 {
        self.0 as f64 / 4.0
    }

    /// The filter's integer oversampling ([`crate::filter::Filter::new`]):
    /// 2 for σ = 2, else 1; the Kaiser–Bessel shape is designed for
    /// [`GridOversampling::factor`]
    /// ([`crate::filter::Filter::with_design_oversampling`]).
    pub const fn integer(self) -> u32 {
        if self.0 >= 8 {
            2
        } else {
            1
        }
    }

    /// `true` for a power-of-two side (σ = 1 or 2).
    pub const fn is_pow2(self) -> bool {
        self.0 == 4 || self.0 == 8
    }

    /// The cube side for `dims`: [`padded_size`] for σ = 1 or 2; else the
    /// smallest even `2^a·3^b·5^c` at least `σ·max(nx, ny, nz)`.
    ///
    /// # Errors
    /// As [`padded_size`].
    pub fn side(self, dims: [usize; 3]) -> Result<usize> {
        if self.is_pow2() {
            return padded_size(dims, self.integer());
        }
        if dims.contains(&0) {
            return Err(Error::EmptyVolume);
        }
        let largest = dims.iter().copied().max().unwrap_or(1);
        largest
            .checked_mul(self.0 as usize)
            .map(|q| q.div_ceil(8))
            .and_then(crate::dht::fast_len)
            .and_then(|h| h.checked_mul(2))
            .ok_or(Error::VolumeTooLarge { dims, grid: 0 })
    }
}

/// `Ok` if a spectrum of side `n` can hold a volume of `dims` premultiplied
/// for a filter of integer oversampling `oversample`: `n` is
/// [`padded_size`]`(dims, oversample)`, or an even `2^a·3^b·5^c` from
/// `oversample·max(dims)` up to `padded_size(dims, 2·oversample)` (the
/// mixed-radix grids of [`GridOversampling`]).
///
/// # Errors
/// [`Error::VolumeTooLarge`] naming `n` otherwise; as [`padded_size`].
pub fn check_side(dims: [usize; 3], oversample: u32, n: usize) -> Result<()> {
    let pow2 = padded_size(dims, oversample)?;
    if n == pow2 {
        return Ok(());
    }
    let largest = dims.iter().copied().max().unwrap_or(1);
    let low = largest.saturating_mul(oversample as usize);
    let high = padded_size(dims, oversample.saturating_mul(2))?;
    if n % 2 == 0 && crate::dht::is_fast_len(n) && n >= low && n <= high {
        Ok(())
    } else {
        Err(Error::VolumeTooLarge { dims, grid: n })
    }
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
