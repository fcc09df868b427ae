//! `fvr render --view anterior|posterior|left|right|superior|inferior`:
//! views named in the patient's frame, turned into `--dir` and `--up` by
//! the volume's orientation ([`fvr_engine::volume::Orientation`], RAS).
//!
//! Each view is what a viewer standing on that side of the patient sees,
//! looking at the patient: anterior, posterior, left and right with the
//! patient's superior up; superior and inferior with the patient's anterior
//! up. An anterior view therefore shows the patient's right on the image's
//! left and an inferior view (from the feet, as axial images are read) the
//! same, as radiographs are displayed; posterior and superior views are the
//! mirror images of those.

use clap::{Args, ValueEnum};
use fvr_core::geometry::View;
use fvr_engine::volume::{Orientation, Volume};

/// A view named by the side of the patient it is taken from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum Anatomical {
    /// From the front: the patient's right on the image's left.
    Anterior,
    /// From behind: the patient's right on the image's right.
    Posterior,
    /// From the patient's left: the face to the image's left.
    Left,
    /// From the patient's right: the face to the image's right.
    Right,
    /// From above the head, anterior up: the patient's right on the right.
    Superior,
    /// From below the feet, anterior up: the patient's right on the left.
    Inferior,
}

impl Anatomical {
    /// The view direction (from the eye into the patient) and up vector in
    /// RAS.
    pub(crate) fn ras(self) -> ([f64; 3], [f64; 3]) {
        const S: [f64; 3] = [0.0, 0.0, 1.0];
        const A: [f64; 3] = [0.0, 1.0, 0.0];
        match self {
            Anatomical::Anterior => ([0.0, -1.0, 0.0], S),
            Anatomical::Posterior => ([0.0, 1.0, 0.0], S),
            Anatomical::Left => ([1.0, 0.0, 0.0], S),
            Anatomical::Right => ([-1.0, 0.0, 0.0], S),
            Anatomical::Superior => ([0.0, 0.0, -1.0], A),
            Anatomical::Inferior => ([0.0, 0.0, 1.0], A),
        }
    }

    /// The view in the volume's frame: by its orientation, or, for a
    /// volume without one, with its x, y, z taken as the patient's right,
    /// anterior and superior (a note on stderr says so).
    ///
    /// A volume stored in a left-handed frame (a direction matrix of
    /// determinant < 0, which the NIfTI reader's reordering leaves only for
    /// oblique files) is first flipped along x, as that reader flips axes:
    /// no view direction of a left-handed frame shows the patient unmirrored.
    pub(crate) fn view_of(self, volume: &mut Volume, name: &str) -> View {
        if let Some(o) = volume.orientation.filter(|o| o.det() < 0.0) {
            let (world, flip) = ([0, 1, 2], [true, false, false]);
            let (dims, spacing) = (volume.dims, volume.spacing);
            let map = fvr_host::io::nifti::AxisMap {
                world,
                flip,
                source: "view",
            };
            map.apply(volume);
            volume.orientation = Some(o.permuted(world, flip, dims, spacing));
        }
        let orientation = volume.orientation.unwrap_or_else(|| {
            eprintln!(
                "fvr: note: {name} carries no orientation; --view takes its x, y, z axes as the \
                 patient's right, anterior and superior (RAS)"
            );
            Orientation::IDENTITY
        });
        let (dir, up) = self.ras();
        View {
            dir: orientation.to_volume(dir),
            up: orientation.to_volume(up),
        }
    }
}

/// The `--view` flag of `fvr render`.
#[derive(Args, Clone, Copy, Default)]
pub(crate) struct AnatomyArgs {
    /// A view named in the patient's frame, from the file's orientation
    /// (NIfTI sform/qform, NRRD space directions, DICOM
    /// ImageOrientationPatient): anterior, posterior, left, right (superior
    /// up), superior, inferior (anterior up). An anterior or inferior view
    /// shows the patient's right on the image's left. Volumes without an
    /// orientation are taken as RAS, with a note.
    #[arg(long, value_enum, conflicts_with_all = ["dir", "up", "light_ring"])]
    pub(crate) view: Option<Anatomical>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The image's right vector `dir × up` in RAS for each view.
    #[test]
    fn image_right_in_the_patient() {
        let right = |v: Anatomical| {
            let (d, u) = v.ras();
            [
                d[1] * u[2] - d[2] * u[1],
                d[2] * u[0] - d[0] * u[2],
                d[0] * u[1] - d[1] * u[0],
            ]
        };
        // Patient's left (−R) on the image's right: their right on its left.
        assert_eq!(right(Anatomical::Anterior), [-1.0, 0.0, 0.0]);
        assert_eq!(right(Anatomical::Inferior), [-1.0, 0.0, 0.0]);
        assert_eq!(right(Anatomical::Posterior), [1.0, 0.0, 0.0]);
        assert_eq!(right(Anatomical::Superior), [1.0, 0.0, 0.0]);
        // Lateral views: the face (anterior) to the left from the left.
        assert_eq!(right(Anatomical::Left), [0.0, -1.0, 0.0]);
        assert_eq!(right(Anatomical::Right), [0.0, 1.0, 0.0]);
    }
}
