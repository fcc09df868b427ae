//! Choosing the interpolation filter for a volume: the Kaiser–Bessel shape
//! and the oversampling that keeps premultiplication well conditioned.

use std::str::FromStr;

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::volume::{padded_size, DenseVolume};

use crate::volume::Volume;

/// How the Kaiser–Bessel shape parameter is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum KbDesign {
    /// Fitted to the volume's energy distribution ([`Filter::fit`]).
    Auto,
    /// Beatty's β for this design oversampling.
    Sigma(f64),
}

impl FromStr for KbDesign {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(KbDesign::Auto);
        }
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 1.0 => Ok(KbDesign::Sigma(v)),
            _ => Err(format!(
                "kb design `{s}` must be `auto` or an oversampling factor >= 1"
            )),
        }
    }
}

/// Choose the filter for `volume`.
///
/// # Errors
/// As [`Filter::fit`].
pub fn choose_filter(
    volume: &Volume,
    kind: FilterKind,
    oversample: u32,
    design: KbDesign,
) -> Result<Filter, fvr_core::Error> {
    match design {
        KbDesign::Auto => {
            let src = DenseVolume::new(volume.dims, &volume.data)?;
            Ok(Filter::fit(kind, oversample, &src)?.0)
        }
        KbDesign::Sigma(s) => Filter::with_design_oversampling(kind, oversample, s),
    }
}

/// Above this [`premultiplication_gain_db`], [`choose_oversampling`] pads the
/// grid to oversampling 2.
///
/// Why 20 dB: the f16 spectrum of compact data sits 75–84 dB from f64
/// (README); a gain of 20 dB would leave about 55–64 dB, the most the
/// default format can give away and still stay above the paper's 50 dB.
pub const CONDITIONING_LIMIT_DB: f64 = 20.0;

/// How much premultiplication amplifies storage rounding noise relative to
/// the image, in dB: `10·log10(Σg² / (p₀⁶·Σf²))`, where `g = f·p(x)p(y)p(z)`
/// is the premultiplied volume, `p` the per-axis factor `1/ĥ` on the padded
/// grid and `p₀ = p(0)` its value at the centre.
///
/// Rounding adds noise proportional to each stored coefficient, so the noise
/// energy of an image is proportional to `Σg²` (Parseval), while its signal
/// is that of `p₀³·f`. A volume confined to the middle of its grid has a gain
/// near 0 dB. One that fills the grid at oversampling 1 has its faces and
/// corners multiplied by `p(n/2)/p₀` per axis (about 200 for kb4, so up to
/// 10⁷ at a corner), which no 16-bit format can absorb: the gain is then
/// 60–90 dB. Returns 0 for an all-zero volume.
///
/// # Errors
/// A NaN or infinite voxel, or an empty volume.
pub fn premultiplication_gain_db(volume: &Volume, filter: Filter) -> Result<f64, fvr_core::Error> {
    let n = padded_size(volume.dims, filter.oversample())?;
    let mut table = vec![0.0f64; n];
    fvr_core::spectrum::premultiplier_table(&filter, n, &mut table);
    let p0 = table[0];
    let dims = volume.dims;
    let factor = |i: usize, a: usize| table[(i + n - dims[a] / 2) & (n - 1)] / p0;
    let (mut g2, mut f2) = (0.0f64, 0.0f64);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            let pyz = factor(j, 1) * factor(k, 2);
            for i in 0..dims[0] {
                let v = volume.get(i, j, k) as f64;
                if !v.is_finite() {
                    return Err(fvr_core::Error::NonFiniteVoxel {
                        index: [i, j, k],
                        value: v,
                    });
                }
                let g = v * factor(i, 0) * pyz;
                g2 += g * g;
                f2 += v * v;
            }
        }
    }
    Ok(if f2 > 0.0 {
        10.0 * (g2 / f2).log10()
    } else {
        0.0
    })
}

/// The oversampling for `volume`: 1, unless premultiplying for `kind` at
/// oversampling 1 would amplify storage noise by more than
/// [`CONDITIONING_LIMIT_DB`] ([`premultiplication_gain_db`]); then 2, where
/// the data fills only the middle half of each axis and the gain is a few dB.
///
/// This is the remedy for the ill-conditioning of Kaiser–Bessel
/// premultiplication on data that fills its grid (a constant volume, or CT
/// in Hounsfield units, whose air is −1000): the f64 image there is itself
/// wrong at the faces (the kernel's first alias is as strong as its main
/// lobe at ν = ½), and the amplified faces swamp every 16-bit format.
///
/// # Errors
/// As [`choose_filter`] and [`premultiplication_gain_db`].
pub fn choose_oversampling(
    volume: &Volume,
    kind: FilterKind,
    design: KbDesign,
) -> Result<u32, fvr_core::Error> {
    let filter = choose_filter(volume, kind, 1, design)?;
    let gain = premultiplication_gain_db(volume, filter)?;
    Ok(if gain > CONDITIONING_LIMIT_DB { 2 } else { 1 })
}
