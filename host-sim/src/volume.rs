//! An owned 3D volume of f32 samples, the host-side input to the core.

use std::fmt;

/// Voxel spacing when a format gives none: 1 mm on every axis.
pub const DEFAULT_SPACING: [f64; 3] = [1.0, 1.0, 1.0];

/// A dense 3D volume. Voxel `(i, j, k)` is stored at `i + nx * (j + ny * k)`:
/// `i` is the fastest axis, as in NRRD, NIfTI and raw files.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Sizes `[nx, ny, nz]`.
    pub dims: [usize; 3],
    /// Samples, `nx * ny * nz` of them, `i` fastest.
    pub data: Vec<f32>,
    /// Physical distance between neighbouring samples along `i`, `j` and `k`,
    /// in millimetres: finite and positive ([`check_spacing`]).
    /// [`DEFAULT_SPACING`] when the source gives none.
    pub spacing: [f64; 3],
}

impl Volume {
    /// A volume of `data` (`i` fastest) with [`DEFAULT_SPACING`].
    ///
    /// # Panics
    /// If `data.len()` is not the product of `dims`: callers build the data
    /// for the dims they pass.
    pub fn new(dims: [usize; 3], data: Vec<f32>) -> Self {
        assert_eq!(
            Some(data.len()),
            dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d)),
            "Volume::new: {} samples for dims {dims:?}",
            data.len()
        );
        Self {
            dims,
            data,
            spacing: DEFAULT_SPACING,
        }
    }

    /// A volume of zeros with [`DEFAULT_SPACING`].
    pub fn zeros(dims: [usize; 3]) -> Self {
        Self::new(dims, vec![0.0; dims[0] * dims[1] * dims[2]])
    }

    /// This volume with voxel spacing `spacing` (mm).
    ///
    /// # Errors
    /// A spacing that is zero, negative or not finite ([`check_spacing`]).
    pub fn with_spacing(mut self, spacing: [f64; 3]) -> Result<Self, SpacingError> {
        self.spacing = check_spacing(spacing)?;
        Ok(self)
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

    /// Make `background` the zero of the volume: every sample becomes
    /// `max(x − background, 0)`.
    ///
    /// An X-ray sums the samples along each ray, so empty space must be 0.
    /// CT in Hounsfield units has air at −1024: without this, air would
    /// count as negative density and the volume's box would show.
    ///
    /// # Errors
    /// A `background` that is not finite.
    pub fn subtract_background(&mut self, background: f64) -> Result<(), String> {
        if !background.is_finite() {
            return Err(format!("background {background} must be a finite number"));
        }
        for v in &mut self.data {
            *v = ((*v as f64 - background).max(0.0)) as f32;
        }
        Ok(())
    }

    /// Physical extent `dims × spacing` in mm per axis.
    pub fn extent_mm(&self) -> [f64; 3] {
        [0, 1, 2].map(|a| self.dims[a] as f64 * self.spacing[a])
    }
}

/// A voxel spacing that is zero, negative or not finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpacingError {
    /// Axis 0, 1 or 2 (`i`, `j`, `k`).
    pub axis: usize,
    /// The offending value.
    pub value: f64,
}

impl fmt::Display for SpacingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = if self.value.is_nan() {
            "not a number"
        } else if self.value.is_infinite() {
            "infinite"
        } else if self.value == 0.0 {
            "zero"
        } else {
            "negative"
        };
        write!(
            f,
            "voxel spacing {} along axis {} is {what}; spacings must be finite and positive (mm)",
            self.value,
            ["i (x)", "j (y)", "k (z)"][self.axis.min(2)]
        )
    }
}

impl std::error::Error for SpacingError {}

/// `spacing` if every component is finite and positive.
///
/// # Errors
/// The first axis whose spacing is zero, negative, infinite or NaN.
pub fn check_spacing(spacing: [f64; 3]) -> Result<[f64; 3], SpacingError> {
    match spacing.iter().position(|&s| !(s.is_finite() && s > 0.0)) {
        None => Ok(spacing),
        Some(axis) => Err(SpacingError {
            axis,
            value: spacing[axis],
        }),
    }
}
