//! The core's error type. Every fallible entry point returns [`Result`]; the
//! core never panics on data.

use core::fmt;

/// What went wrong. The `Display` text names the offending quantity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Error {
    /// A transform or grid length that must be a power of two is not.
    NotPowerOfTwo {
        /// Which length.
        what: &'static str,
        /// The length given.
        len: usize,
    },
    /// A caller-provided buffer is shorter than required.
    BufferTooSmall {
        /// Which buffer.
        what: &'static str,
        /// Elements required.
        needed: usize,
        /// Elements provided.
        got: usize,
    },
    /// A buffer whose length must match a shape exactly does not.
    LengthMismatch {
        /// Which buffer.
        what: &'static str,
        /// Elements expected.
        expected: usize,
        /// Elements provided.
        got: usize,
    },
    /// The twiddle table was built for a size the transform cannot use.
    TwiddlesTooShort {
        /// Size the table was built for.
        table_len: usize,
        /// Size the transform needs.
        needed: usize,
    },
    /// The view direction is zero, or the up hint is zero.
    ZeroViewVector {
        /// View direction as given.
        dir: [f64; 3],
        /// Up hint as given.
        up: [f64; 3],
    },
    /// The view direction or the up hint is too short to normalise: not
    /// zero, but every component subnormal (below `2^−1022`).
    ShortViewVector {
        /// View direction as given.
        dir: [f64; 3],
        /// Up hint as given.
        up: [f64; 3],
    },
    /// The up hint is parallel to the view direction.
    ParallelViewVectors {
        /// View direction as given.
        dir: [f64; 3],
        /// Up hint as given.
        up: [f64; 3],
    },
    /// A view vector has a NaN or infinite component.
    NonFiniteViewVector {
        /// View direction as given.
        dir: [f64; 3],
        /// Up hint as given.
        up: [f64; 3],
    },
    /// The requested image is larger than the spectrum's grid.
    ImageTooLarge {
        /// Requested width.
        width: usize,
        /// Requested height.
        height: usize,
        /// The largest allowed side (the padded grid size).
        grid: usize,
    },
    /// An image side of zero.
    EmptyImage,
    /// The volume does not fit into the padded grid.
    VolumeTooLarge {
        /// Volume dimensions.
        dims: [usize; 3],
        /// Padded grid side.
        grid: usize,
    },
    /// A volume with a zero dimension.
    EmptyVolume,
    /// A voxel is NaN or infinite.
    NonFiniteVoxel {
        /// Voxel index `(i, j, k)`.
        index: [usize; 3],
        /// Its value.
        value: f64,
    },
    /// A value left the storage format's finite range during a transform.
    Overflow {
        /// Which pass overflowed.
        stage: &'static str,
    },
    /// An oversampling factor other than 1 or 2.
    UnsupportedOversampling {
        /// The factor given.
        factor: u32,
    },
    /// The spectrum was prepared for another filter than the one asked for.
    FilterMismatch,
    /// A scene parameter is NaN, infinite, or outside its documented range.
    InvalidSceneValue {
        /// Which parameter (e.g. "light colour", "depth-cue front weight").
        what: &'static str,
        /// Index of the light or profile point it belongs to (0 if none).
        index: usize,
        /// The value given.
        value: f64,
    },
    /// A light's direction is too short to normalise (every component
    /// subnormal).
    ShortLightVector {
        /// Index of the light.
        index: usize,
    },
    /// A light direction is zero.
    ZeroLightVector {
        /// Index of the light.
        index: usize,
    },
    /// More items than a fixed-capacity scene can hold.
    TooMany {
        /// What (e.g. "lights", "depth-profile points").
        what: &'static str,
        /// How many were given.
        given: usize,
        /// The capacity.
        capacity: usize,
    },
    /// The filter's kernel has no usable derivative for gradient-based
    /// depth cueing (nearest neighbour: its derivative is two impulses).
    NoKernelDerivative,
    /// The scene has directional lights but no `|∇f|` spectrum was given,
    /// or the one given does not match the density spectrum.
    GradientSpectrum {
        /// What is wrong with it.
        problem: &'static str,
    },
    /// A stored table (e.g. a kernel table from flash) holds a NaN or
    /// infinite entry.
    NonFiniteTableEntry {
        /// Which table.
        what: &'static str,
        /// Index of the first bad entry.
        index: usize,
    },
    /// A minifloat whose sign, exponent and mantissa bits do not add up to
    /// 16 (or 8).
    BadMinifloatSplit {
        /// Exponent bits asked for.
        exponent: u32,
        /// Mantissa bits asked for.
        mantissa: u32,
    },
    /// A block size that does not divide the line of the spectrum.
    BlockSizeMismatch {
        /// The block (brick) side.
        block: usize,
        /// The line length (the spectrum's side).
        line: usize,
    },
    /// A voxel spacing that is zero, negative, NaN or infinite.
    InvalidSpacing {
        /// The axis (0 = `i`, 1 = `j`, 2 = `k`).
        axis: usize,
        /// The spacing given (mm).
        value: f64,
    },
    /// An image pixel size that is zero, negative, NaN or infinite.
    InvalidPixelSize {
        /// The pixel size given (mm).
        value: f64,
    },
    /// Valid spacing and pixel size whose ratios or gain `Δx·Δy·Δz/p²`
    /// overflow or underflow f64.
    SamplingOutOfRange {
        /// The spacing given (mm).
        spacing: [f64; 3],
        /// The pixel size given (mm).
        pixel_size: f64,
    },
    /// A storage format the target cannot store or prepare this way.
    UnsupportedFormat {
        /// Which format.
        format: &'static str,
        /// Why not.
        reason: &'static str,
    },
    /// A scene ([`crate::shading::Scene`]) was asked for in a rendering it
    /// does not support (a progressive level, or physical units).
    SceneUnsupported {
        /// What was asked for.
        what: &'static str,
    },
    /// The volume's magnitude is too small or too large for the preparation
    /// arithmetic to bring it to the storage format's working range.
    MagnitudeOutOfRange {
        /// `Σ|premultiplied voxel|`, the quantity the scale is derived from.
        sum: f64,
        /// The power-of-two scale that would be needed.
        scale: f64,
    },
    /// A mixed-radix transform length that is zero or has a prime factor
    /// above 5.
    UnsupportedLength {
        /// The length given.
        len: usize,
    },
    /// A stored integer table (e.g. fixed-point twiddles from flash) holds
    /// an entry outside the range its arithmetic is proved safe for.
    TableEntryOutOfRange {
        /// Which table.
        what: &'static str,
        /// Index of the first bad entry.
        index: usize,
    },
    /// A value outside the range the fixed-point pipeline's overflow proof
    /// covers (e.g. a slice axis component beyond ±16 index units).
    FixedPointRange {
        /// What was out of range, and the range.
        what: &'static str,
    },
}

/// Shorthand for results of this crate.
pub type Result<T> = core::result::Result<T, Error>;

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::NotPowerOfTwo { what, len } => {
                write!(f, "{what} must be a power of two, got {len}")
            }
            Error::BufferTooSmall { what, needed, got } => {
                write!(f, "{what} holds {got} elements, needs at least {needed}")
            }
            Error::LengthMismatch { what, expected, got } => {
                write!(f, "{what} holds {got} elements, expected exactly {expected}")
            }
            Error::TwiddlesTooShort { table_len, needed } => write!(
                f,
                "twiddle table built for length {table_len} cannot serve a transform of length {needed}"
            ),
            Error::ZeroViewVector { dir, up } => write!(
                f,
                "zero view vector: direction {} and up {} must both be non-zero",
                V3(dir),
                V3(up)
            ),
            Error::ShortViewVector { dir, up } => write!(
                f,
                "view direction {} or up {} is too short to normalise (its components are \
                 subnormal numbers): give components of ordinary size, such as 1,0,0",
                V3(dir),
                V3(up)
            ),
            Error::ParallelViewVectors { dir, up } => write!(
                f,
                "view direction {} is parallel to up {}: choose another --up",
                V3(dir),
                V3(up)
            ),
            Error::NonFiniteViewVector { dir, up } => write!(
                f,
                "view vectors must be finite: direction {}, up {}",
                V3(dir),
                V3(up)
            ),
            Error::ImageTooLarge { width, height, grid } => write!(
                f,
                "image size {width}x{height} exceeds the padded grid size {grid}"
            ),
            Error::EmptyImage => write!(f, "image width and height must be at least 1"),
            Error::VolumeTooLarge { dims, grid } => write!(
                f,
                "volume {}x{}x{} does not fit a padded grid of side {grid}",
                dims[0], dims[1], dims[2]
            ),
            Error::EmptyVolume => write!(f, "volume has a zero dimension"),
            Error::NonFiniteVoxel { index, value } => write!(
                f,
                "voxel ({}, {}, {}) is {}: NaN and infinite voxels cannot be rendered",
                index[0],
                index[1],
                index[2],
                Num(value)
            ),
            Error::Overflow { stage } => write!(
                f,
                "value overflowed the storage format during the {stage}"
            ),
            Error::UnsupportedOversampling { factor } => {
                write!(f, "oversampling factor must be 1 or 2, got {factor}")
            }
            Error::FilterMismatch => write!(
                f,
                "the spectrum was premultiplied for a different filter or oversampling"
            ),
            Error::InvalidSceneValue { what, index, value } => {
                write!(f, "{what} #{index} is {}, which is not allowed", Num(value))
            }
            Error::ShortLightVector { index } => write!(
                f,
                "light #{index} has a direction too short to normalise (its components are \
                 subnormal numbers): give components of ordinary size, such as 1,0,0"
            ),
            Error::ZeroLightVector { index } => write!(
                f,
                "light #{index} has a zero direction vector: give the direction towards the light"
            ),
            Error::TooMany {
                what,
                given,
                capacity,
            } => write!(f, "{given} {what} given, but a scene holds at most {capacity}"),
            Error::NoKernelDerivative => write!(
                f,
                "the nearest-neighbour kernel has no usable derivative: linear depth cueing needs another filter"
            ),
            Error::SceneUnsupported { what } => {
                write!(f, "scenes are rendered at level 0 in voxel units, not {what}")
            }
            Error::GradientSpectrum { problem } => {
                write!(f, "gradient-magnitude spectrum: {problem}")
            }
            Error::NonFiniteTableEntry { what, index } => {
                write!(f, "{what} entry {index} is NaN or infinite")
            }
            Error::BadMinifloatSplit { exponent, mantissa } => write!(
                f,
                "minifloat split e{exponent}m{mantissa} has 1 + {exponent} + {mantissa} = {} bits; \
                 sign, exponent and mantissa must add up to 16 (or 8)",
                1u64 + exponent as u64 + mantissa as u64
            ),
            Error::BlockSizeMismatch { block, line } => write!(
                f,
                "block size {block} does not divide the spectrum's line of {line} values"
            ),
            Error::InvalidSpacing { axis, value } => write!(
                f,
                "voxel spacing {} along axis {} is not allowed: spacings must be finite and positive (mm)",
                Num(value),
                ["i (x)", "j (y)", "k (z)"][axis.min(2)]
            ),
            Error::InvalidPixelSize { value } => write!(
                f,
                "pixel size {} is not allowed: it must be finite and positive (mm)",
                Num(value)
            ),
            Error::SamplingOutOfRange {
                spacing,
                pixel_size,
            } => write!(
                f,
                "voxel spacing {} mm and pixel size {} mm are too far apart: \
                 their ratios or the gain spacing volume / pixel area leave the f64 range",
                V3(spacing),
                Num(pixel_size)
            ),
            Error::UnsupportedFormat { format, reason } => {
                write!(f, "storage format {format} is not supported here: {reason}")
            }
            Error::MagnitudeOutOfRange { sum, scale } => write!(
                f,
                "the volume's magnitude (sum of |premultiplied voxels| {}) needs a scale of {}, \
                 under which the premultiplied values leave the preparation arithmetic's range; \
                 rescale the voxel values",
                Num(sum),
                Num(scale)
            ),
            Error::UnsupportedLength { len } => write!(
                f,
                "transform length {len} is not 2^a·3^b·5^c (at least 1, no prime factor above 5)"
            ),
            Error::TableEntryOutOfRange { what, index } => {
                write!(f, "{what} entry {index} is out of range")
            }
            Error::FixedPointRange { what } => {
                write!(f, "out of the fixed-point pipeline's range: {what}")
            }
        }
    }
}

/// Lets host code carry a core error as a source (`?` into `Box<dyn Error>`,
/// `thiserror`'s `#[from]`) instead of flattening it to a string.
impl core::error::Error for Error {}

struct V3([f64; 3]);

impl fmt::Display for V3 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.0.map(Num);
        write!(f, "({x}, {y}, {z})")
    }
}

/// A number as `{}` prints it, or as `{:e}` when that would be long (at or
/// beyond 1e6, or below 1e-4 but not zero), so messages stay one short line.
struct Num(f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let a = self.0.abs();
        if a.is_finite() && a != 0.0 && !(1e-4..1e6).contains(&a) {
            write!(f, "{:e}", self.0)
        } else {
            write!(f, "{}", self.0)
        }
    }
}

#[cold]
pub(crate) fn not_power_of_two(what: &'static str, len: usize) -> Error {
    Error::NotPowerOfTwo { what, len }
}

#[cold]
pub(crate) fn too_small(what: &'static str, needed: usize, got: usize) -> Error {
    Error::BufferTooSmall { what, needed, got }
}

#[cold]
pub(crate) fn mismatch(what: &'static str, expected: usize, got: usize) -> Error {
    Error::LengthMismatch {
        what,
        expected,
        got,
    }
}

/// `Ok` if `len` is a power of two (1 counts), else the named error.
#[inline]
pub(crate) fn require_pow2(what: &'static str, len: usize) -> Result<()> {
    if len.is_power_of_two() {
        Ok(())
    } else {
        Err(not_power_of_two(what, len))
    }
}

/// `Ok` if `got >= needed`, else the named error.
#[inline]
pub(crate) fn require_len(what: &'static str, needed: usize, got: usize) -> Result<()> {
    if got >= needed {
        Ok(())
    } else {
        Err(too_small(what, needed, got))
    }
}

/// `Ok` if `got == expected`, else [`Error::LengthMismatch`].
#[inline]
pub(crate) fn check_len(what: &'static str, expected: usize, got: usize) -> Result<()> {
    if expected == got {
        Ok(())
    } else {
        Err(mismatch(what, expected, got))
    }
}
