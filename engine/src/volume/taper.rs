//! A taper for content the box cuts: a CT head ends at the neck with a
//! flat face of tissue, and that face, seen edge on, projects to a step.
//!
//! The spectrum of a voxel volume is that of its trigonometric
//! interpolant, so a frequency-domain projection (the paper's eq. 1–3) of a
//! step rings beside it (Gibbs): on the CT head's lateral view the rows just
//! past the neck dip below zero. A spatial projector, which interpolates
//! linearly, shows no such ringing. Fading the cut content to zero over a
//! few voxels with a raised cosine turns the step into a smooth ramp, whose
//! spectrum decays fast, at the price of changing those voxels: the
//! tapered volume is another object, which the docs quantify (docs/cli.md,
//! "Cut volumes").
//!
//! Only faces that cut content are tapered ([`cut_faces`]), so a volume whose
//! faces hold nothing (every phantom) is left bit for bit as it was.

use super::Volume;

/// A face of the voxel box is cut when at least [`CUT_AREA`] of its
/// outermost slab holds content, a sample of at least this share of the
/// volume's largest magnitude: 5 % sits above CT noise in air and well below
/// soft tissue at a cut (about a quarter of bone's attenuation).
pub const CUT_SHARE: f32 = 0.05;

/// The share of a face's slab that content must cover for the face to be
/// cut: 1 %, so that stray voxels (noise, a lone artefact) on a face do not
/// count. On the CT head (air at 0), the neck's face is 43 % covered, the
/// couch's 38 %, the crown's 2.7 % and the sides' 0.2 %.
pub const CUT_AREA: f64 = 0.01;

/// Voxels `--taper` fades over when given without a width.
pub const DEFAULT_TAPER_VOXELS: usize = 8;

/// The six faces of the box, in the order [`Faces`] holds them: the low
/// and high faces along `i`, `j` and `k`.
pub const FACE_NAMES: [&str; 6] = ["i-", "i+", "j-", "j+", "k-", "k+"];

/// Which faces of the box (in [`FACE_NAMES`] order) cut content.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Faces(pub [bool; 6]);

impl Faces {
    /// Whether no face is marked.
    pub fn none(&self) -> bool {
        !self.0.iter().any(|&f| f)
    }

    /// The marked faces' names ([`FACE_NAMES`]).
    pub fn names(&self) -> Vec<&'static str> {
        FACE_NAMES
            .iter()
            .zip(self.0)
            .filter_map(|(name, on)| on.then_some(*name))
            .collect()
    }
}

/// The faces whose outermost slab holds content over [`CUT_AREA`] of it
/// (samples of [`CUT_SHARE`] of the volume's largest magnitude or more).
/// None for an all-zero volume.
pub fn cut_faces(volume: &Volume) -> Faces {
    let peak = volume.data.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    if peak == 0.0 {
        return Faces::default();
    }
    let floor = CUT_SHARE * peak;
    let [nx, ny, nz] = volume.dims;
    let content = |v: &f32| usize::from(v.abs() >= floor);
    let mut count = [0usize; 6];
    for k in 0..nz {
        for j in 0..ny {
            let row = &volume.data[volume.index(0, j, k)..][..nx];
            count[0] += content(&row[0]);
            count[1] += content(&row[nx - 1]);
            let in_row = || row.iter().map(content).sum::<usize>();
            if j == 0 {
                count[2] += in_row();
            }
            if j == ny - 1 {
                count[3] += in_row();
            }
            if k == 0 {
                count[4] += in_row();
            }
            if k == nz - 1 {
                count[5] += in_row();
            }
        }
    }
    let area = [ny * nz, ny * nz, nx * nz, nx * nz, nx * ny, nx * ny];
    Faces(core::array::from_fn(|f| {
        count[f] > 0 && count[f] as f64 >= CUT_AREA * area[f] as f64
    }))
}

/// The weight of the voxel `d` voxels in from a tapered face (0 on the
/// face): `sin²(π/2 · (d + 1)/(width + 1))` for `d < width`, a raised
/// cosine rising from near 0 to near 1, and 1 beyond.
pub fn ramp(d: usize, width: usize) -> f32 {
    if d >= width {
        return 1.0;
    }
    let s = (core::f64::consts::FRAC_PI_2 * (d + 1) as f64 / (width + 1) as f64).sin();
    (s * s) as f32
}

/// Fade the content of every cut face ([`cut_faces`]) to zero over `width`
/// voxels ([`ramp`]); where two tapered faces meet the weights multiply.
/// Returns the faces tapered (none: the volume is unchanged).
///
/// # Errors
/// `width` is 0, or a cut axis has fewer than `2 · width` voxels; the
/// volume is then unchanged.
pub fn taper_cut_faces(volume: &mut Volume, width: usize) -> Result<Faces, String> {
    if width == 0 {
        return Err("--taper 0: give the width of the taper in voxels, 1 or more".into());
    }
    let faces = cut_faces(volume);
    for axis in 0..3 {
        let cut = faces.0[2 * axis] || faces.0[2 * axis + 1];
        let d = volume.dims[axis];
        if cut && 2 * width > d {
            return Err(format!(
                "--taper {width}: the volume has {d} voxels along {} and the content it cuts \
                 there needs a taper of at most {} voxels",
                ["i", "j", "k"][axis],
                d / 2
            ));
        }
    }
    if faces.none() {
        return Ok(faces);
    }
    // One weight per index along each axis: the product of the ramps of
    // that axis's tapered faces (1 elsewhere, so untouched voxels keep
    // their bits).
    let weights: [Vec<f32>; 3] = core::array::from_fn(|axis| {
        let d = volume.dims[axis];
        (0..d)
            .map(|i| {
                let low = if faces.0[2 * axis] {
                    ramp(i, width)
                } else {
                    1.0
                };
                let high = if faces.0[2 * axis + 1] {
                    ramp(d - 1 - i, width)
                } else {
                    1.0
                };
                low * high
            })
            .collect()
    });
    let [nx, ny, _] = volume.dims;
    for (z, plane) in volume.data.chunks_exact_mut(nx * ny).enumerate() {
        let wz = weights[2][z];
        for (y, row) in plane.chunks_exact_mut(nx).enumerate() {
            let wzy = wz * weights[1][y];
            if wzy == 1.0 && !faces.0[0] && !faces.0[1] {
                continue;
            }
            for (v, wx) in row.iter_mut().zip(&weights[0]) {
                *v *= wzy * wx;
            }
        }
    }
    Ok(faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box of ones with a zero border, cut by the `k−` face: content
    /// touches it only there.
    fn cut_box() -> Volume {
        let dims = [12, 10, 20];
        let mut v = Volume::zeros(dims);
        for k in 0..19 {
            for j in 1..9 {
                for i in 1..11 {
                    let idx = v.index(i, j, k);
                    v.data[idx] = 1.0;
                }
            }
        }
        v
    }

    #[test]
    fn finds_only_the_cut_face() {
        let v = cut_box();
        assert_eq!(cut_faces(&v).names(), vec!["k-"]);
        assert!(cut_faces(&Volume::zeros([4, 4, 4])).none());
    }

    #[test]
    fn faint_or_sparse_faces_are_not_cut() {
        let mut v = cut_box();
        // Sets the top face inside its border (80 of its 120 voxels), one
        // voxel in `every`, so that the side faces stay empty.
        let top = |v: &mut Volume, value: f32, every: usize| {
            for j in 1..9 {
                for i in 1..11 {
                    let idx = v.index(i, j, 19);
                    let n = (j - 1) * 10 + (i - 1);
                    v.data[idx] = if n % every == 0 { value } else { 0.0 };
                }
            }
        };
        // Below the share of the peak: not content.
        top(&mut v, 0.99 * CUT_SHARE, 1);
        assert_eq!(cut_faces(&v).names(), vec!["k-"]);
        // At the share, on every voxel of the face: cut.
        top(&mut v, CUT_SHARE, 1);
        assert_eq!(cut_faces(&v).names(), vec!["k-", "k+"]);
        // One voxel (0.8 % of the face): stray, not cut.
        top(&mut v, 1.0, 80);
        assert_eq!(cut_faces(&v).names(), vec!["k-"]);
        // Two (1.7 %): cut.
        top(&mut v, 1.0, 40);
        assert_eq!(cut_faces(&v).names(), vec!["k-", "k+"]);
    }

    #[test]
    fn ramp_rises_to_one() {
        let w: Vec<f32> = (0..5).map(|d| ramp(d, 4)).collect();
        assert!(w[0] > 0.0 && w[0] < 0.1, "{w:?}");
        assert!(w.windows(2).all(|p| p[0] < p[1]), "{w:?}");
        assert_eq!(w[4], 1.0);
        // Symmetric about the middle: w(d) + w(width − 1 − d) = 1.
        for d in 0..4 {
            assert!((ramp(d, 4) + ramp(3 - d, 4) - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn tapers_the_cut_face_and_nothing_else() {
        let mut v = cut_box();
        let before = v.clone();
        let faces = taper_cut_faces(&mut v, 4).unwrap();
        assert_eq!(faces.names(), vec!["k-"]);
        for k in 0..20 {
            for j in 0..10 {
                for i in 0..12 {
                    let (a, b) = (before.get(i, j, k), v.get(i, j, k));
                    let want = a * ramp(k, 4);
                    assert_eq!(b.to_bits(), want.to_bits(), "voxel ({i}, {j}, {k})");
                    if k >= 4 {
                        assert_eq!(a.to_bits(), b.to_bits(), "voxel ({i}, {j}, {k})");
                    }
                }
            }
        }
    }

    #[test]
    fn uncut_volume_keeps_its_bits() {
        let mut v = Volume::zeros([8, 8, 8]);
        let idx = v.index(4, 4, 4);
        v.data[idx] = 3.0;
        let before = v.clone();
        assert!(taper_cut_faces(&mut v, 2).unwrap().none());
        assert_eq!(v, before);
    }

    #[test]
    fn refuses_a_width_the_volume_cannot_hold() {
        let mut v = cut_box();
        let before = v.clone();
        let e = taper_cut_faces(&mut v, 11).unwrap_err();
        assert!(
            e.contains("20 voxels along k") && e.contains("at most 10"),
            "{e}"
        );
        assert!(taper_cut_faces(&mut v, 0).is_err());
        assert_eq!(v, before);
        // An axis without a cut face does not limit the width.
        assert!(taper_cut_faces(&mut v, 10).is_ok());
    }
}
