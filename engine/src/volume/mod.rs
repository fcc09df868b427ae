//! An owned 3D volume of f32 samples, the host-side input to the core.

mod orientation;
pub mod phantom;
pub mod taper;

pub use orientation::Orientation;

use std::fmt;

/// The samples a resampled volume may have along its longest side: the
/// one rule for `--resample` and a scene's `volume.resample`.
pub const RESAMPLE_RANGE: std::ops::RangeInclusive<usize> = 2..=4096;

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
    /// Where the voxel axes point in the patient, when the source says
    /// (NIfTI sform/qform, NRRD `space directions`, DICOM
    /// `ImageOrientationPatient`); `None` for phantoms and files without.
    pub orientation: Option<Orientation>,
}

/// The most cells a padded cube may have per voxel of the volume before
/// [`check_padding`] refuses it (the cube is padded from the longest axis, so
/// a flat or thin volume wastes the rest).
pub const MAX_PADDING_RATIO: u64 = 256;

/// Cubes up to this many cells (128³ at f16: 4 MiB; 256³ at f16: 32 MiB)
/// are always accepted by [`check_padding`], however thin the volume.
pub const PADDING_FLOOR_CELLS: u64 = 1 << 24;

/// Refuse a volume whose cubic grid of side `n` would hold more than
/// [`MAX_PADDING_RATIO`] cells per voxel (above [`PADDING_FLOOR_CELLS`]):
/// a 1000×1×1 file must not become a 1024³ transform.
///
/// # Errors
/// A one-line message with the dims, the grid and what to do.
pub fn check_padding(dims: [usize; 3], n: usize) -> Result<(), String> {
    let voxels = dims.iter().fold(1u64, |a, &d| a.saturating_mul(d as u64));
    let cells = (n as u64).saturating_pow(3);
    if cells <= PADDING_FLOOR_CELLS || cells <= voxels.saturating_mul(MAX_PADDING_RATIO) {
        return Ok(());
    }
    Err(format!(
        "a {}x{}x{} volume would be padded to a {n}^3 spectrum, {} cells for each of its {voxels} voxels \
         (at most {MAX_PADDING_RATIO}): the grid is a cube as long as the longest axis; \
         crop the long axes or give a volume with more slices",
        dims[0],
        dims[1],
        dims[2],
        cells / voxels.max(1),
    ))
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
            orientation: None,
        }
    }

    /// The dims [`Volume::resample_isotropic`] gives for `largest` samples
    /// along the longest physical side.
    ///
    /// # Errors
    /// `largest` outside [`RESAMPLE_RANGE`].
    pub fn resampled_dims(&self, largest: usize) -> Result<[usize; 3], String> {
        if !RESAMPLE_RANGE.contains(&largest) {
            return Err(format!(
                "resampling to {largest} samples along the longest side: give {} to {}",
                RESAMPLE_RANGE.start(),
                RESAMPLE_RANGE.end()
            ));
        }
        let extent = self.extent_mm();
        let longest = extent.iter().copied().fold(0.0f64, f64::max);
        let h = longest / largest as f64;
        Ok(std::array::from_fn(|a| {
            ((extent[a] / h).round() as usize).clamp(1, largest)
        }))
    }

    /// A volume of zeros with [`DEFAULT_SPACING`].
    pub fn zeros(dims: [usize; 3]) -> Self {
        Self::filled(dims, 0.0)
    }

    /// A volume of `dims` with every voxel `value` and [`DEFAULT_SPACING`].
    pub fn filled(dims: [usize; 3], value: f32) -> Self {
        Self::new(dims, vec![value; dims[0] * dims[1] * dims[2]])
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

    /// The linear index of the first NaN or infinite sample, if any.
    ///
    /// Checked a chunk at a time without a branch per sample (a vector
    /// loop): the planner checks every volume it predicts, and a
    /// `position` over 7 M samples was half of its pass over the CT head.
    pub fn first_non_finite(&self) -> Option<usize> {
        const CHUNK: usize = 1024;
        self.data
            .chunks(CHUNK)
            .enumerate()
            .find(|(_, c)| !c.iter().fold(true, |ok, v| ok & v.is_finite()))
            .and_then(|(at, c)| Some(at * CHUNK + c.iter().position(|v| !v.is_finite())?))
    }

    /// This volume without its last slice along odd axes, so that the
    /// pixels of axis views fall on voxels (the exact reference is then the
    /// voxel sum), in voxel units ([`DEFAULT_SPACING`]).
    pub fn cropped_to_even(&self) -> Volume {
        let dims = self.dims.map(|d| d - d % 2);
        let mut out = Volume::zeros(dims);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let at = out.index(i, j, k);
                    out.data[at] = self.get(i, j, k);
                }
            }
        }
        out
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
        // A background beyond −3.4e38 would turn every voxel into +inf.
        if let Some(&v) = self
            .data
            .iter()
            .find(|&&v| !((v as f64 - background).max(0.0) as f32).is_finite())
        {
            return Err(format!(
                "--background {background:?}: a voxel of {v:?} minus the background exceeds the \
                 largest f32 (3.4e38); give a background of the volume's own scale"
            ));
        }
        for v in &mut self.data {
            *v = ((*v as f64 - background).max(0.0)) as f32;
        }
        Ok(())
    }

    /// This volume resampled to cubic voxels, `largest` samples along its
    /// longest physical side, by trilinear interpolation at the new sample
    /// centres (each new voxel `v` sits at `(v + ½)·h − ½·Δ` in the old
    /// voxel frame, so both grids span the same extent). The spacing becomes
    /// `h = longest extent / largest` on every axis.
    ///
    /// This is the paper's preparation of its CT head ("resampled, then
    /// zero-padded"); trilinear interpolation low-passes the data slightly.
    ///
    /// # Errors
    /// `largest` outside [`RESAMPLE_RANGE`].
    pub fn resample_isotropic(&self, largest: usize) -> Result<Volume, String> {
        let dims = self.resampled_dims(largest)?;
        let h = self.extent_mm().iter().copied().fold(0.0f64, f64::max) / largest as f64;
        let mut data = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        let sample = |a: usize, v: usize| {
            // Old-voxel coordinate of the new sample centre.
            ((v as f64 + 0.5) * h) / self.spacing[a] - 0.5
        };
        let coords: Vec<Vec<(usize, usize, f32)>> = (0..3)
            .map(|a| {
                (0..dims[a])
                    .map(|v| {
                        let x = sample(a, v).clamp(0.0, (self.dims[a] - 1) as f64);
                        let i0 = x.floor() as usize;
                        let i1 = (i0 + 1).min(self.dims[a] - 1);
                        (i0, i1, (x - i0 as f64) as f32)
                    })
                    .collect()
            })
            .collect();
        for &(z0, z1, fz) in &coords[2] {
            for &(y0, y1, fy) in &coords[1] {
                for &(x0, x1, fx) in &coords[0] {
                    let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
                    let plane = |z| {
                        lerp(
                            lerp(self.get(x0, y0, z), self.get(x1, y0, z), fx),
                            lerp(self.get(x0, y1, z), self.get(x1, y1, z), fx),
                            fy,
                        )
                    };
                    data.push(lerp(plane(z0), plane(z1), fz));
                }
            }
        }
        Ok(Volume {
            dims,
            data,
            spacing: [h; 3],
            orientation: self.orientation,
        })
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

#[cfg(test)]
mod tests {
    use super::Volume;

    #[test]
    fn the_first_non_finite_sample_is_found_in_every_chunk_position() {
        let len = 3000;
        assert_eq!(Volume::filled([len, 1, 1], 1.0).first_non_finite(), None);
        for at in [0, 1, 1023, 1024, 1025, 2047, 2999] {
            for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                let mut v = Volume::filled([len, 1, 1], -2.5);
                v.data[at] = bad;
                // A later one never hides the first.
                v.data[len - 1] = f32::NAN;
                assert_eq!(v.first_non_finite(), Some(at), "{bad} at {at}");
            }
        }
        // Extremes that are finite.
        let mut v = Volume::filled([4, 1, 1], f32::MAX);
        v.data[1] = f32::MIN;
        v.data[2] = f32::MIN_POSITIVE / 2.0;
        assert_eq!(v.first_non_finite(), None);
    }

    /// Resampling takes 2 to 4096 samples along the longest side, as the
    /// command line and scene files say, whoever calls it.
    #[test]
    fn resampling_outside_its_range_is_refused() {
        let v = Volume::filled([8, 6, 4], 1.0);
        for bad in [0, 1, 4097, usize::MAX] {
            let e = v.resample_isotropic(bad).unwrap_err();
            assert!(e.contains("give 2 to 4096"), "{bad}: {e}");
        }
        assert_eq!(v.resampled_dims(2).unwrap(), [2, 2, 1]);
        assert_eq!(v.resample_isotropic(16).unwrap().dims, [16, 12, 8]);
    }
}
