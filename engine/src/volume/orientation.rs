//! Where a volume lies in the patient: the direction of each voxel axis and
//! the position of voxel `(0, 0, 0)` in the patient's RAS frame (x to the
//! patient's right, y anterior, z superior, in mm), as a file's
//! orientation fields give them. Readers convert LPS (DICOM, NRRD
//! `left-posterior-superior`) by negating x and y.

/// A volume's placement in the patient's RAS frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orientation {
    /// `direction[w][a]`: RAS component `w` of the unit vector along voxel
    /// axis `a` (the columns are the axes; orthonormal for the usual
    /// scanner geometry, any non-singular matrix accepted).
    pub direction: [[f64; 3]; 3],
    /// RAS position in mm of the centre of voxel `(0, 0, 0)`.
    pub origin: [f64; 3],
}

impl Orientation {
    /// Axes along R, A, S, at the RAS origin.
    pub const IDENTITY: Self = Self {
        direction: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        origin: [0.0; 3],
    };

    /// From a direction matrix whose columns may have any non-zero length
    /// (NRRD `space directions`, an sform's 3×3 part): the columns are
    /// normalized. `None` for a zero, non-finite or singular matrix.
    pub fn from_columns(m: [[f64; 3]; 3], origin: [f64; 3]) -> Option<Self> {
        let mut direction = [[0.0; 3]; 3];
        for a in 0..3 {
            let norm = (0..3).map(|w| m[w][a] * m[w][a]).sum::<f64>().sqrt();
            if !(norm.is_finite() && norm > 0.0) {
                return None;
            }
            for w in 0..3 {
                direction[w][a] = m[w][a] / norm;
            }
        }
        let o = Self { direction, origin };
        (o.det().abs() > 1e-6 && origin.iter().all(|v| v.is_finite())).then_some(o)
    }

    /// Determinant of the direction matrix.
    pub fn det(&self) -> f64 {
        let m = &self.direction;
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    }

    /// The volume-frame vector (components along the voxel axes, in mm)
    /// that points along the RAS vector `p`: `direction⁻¹·p`.
    pub fn to_volume(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.direction;
        let det = self.det();
        // The adjugate over the determinant.
        let inv = [
            [
                m[1][1] * m[2][2] - m[1][2] * m[2][1],
                m[0][2] * m[2][1] - m[0][1] * m[2][2],
                m[0][1] * m[1][2] - m[0][2] * m[1][1],
            ],
            [
                m[1][2] * m[2][0] - m[1][0] * m[2][2],
                m[0][0] * m[2][2] - m[0][2] * m[2][0],
                m[0][2] * m[1][0] - m[0][0] * m[1][2],
            ],
            [
                m[1][0] * m[2][1] - m[1][1] * m[2][0],
                m[0][1] * m[2][0] - m[0][0] * m[2][1],
                m[0][0] * m[1][1] - m[0][1] * m[1][0],
            ],
        ];
        std::array::from_fn(|a| (0..3).map(|w| inv[a][w] * p[w]).sum::<f64>() / det)
    }

    /// LPS ↔ RAS: x and y negated (the same map both ways).
    pub fn flip_lps(v: [f64; 3]) -> [f64; 3] {
        [-v[0], -v[1], v[2]]
    }

    /// The orientation after reordering the volume's axes: file axis `a`
    /// becomes axis `world[a]`, reversed when `flip[a]`, `old_dims[a]`
    /// samples `spacing[a]` mm apart (the reader's reorientation).
    pub fn permuted(
        &self,
        world: [usize; 3],
        flip: [bool; 3],
        old_dims: [usize; 3],
        spacing: [f64; 3],
    ) -> Self {
        let mut out = *self;
        for a in 0..3 {
            let sign = if flip[a] { -1.0 } else { 1.0 };
            for w in 0..3 {
                out.direction[w][world[a]] = sign * self.direction[w][a];
            }
            if flip[a] {
                let far = (old_dims[a].max(1) - 1) as f64 * spacing[a];
                for w in 0..3 {
                    out.origin[w] += self.direction[w][a] * far;
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_and_permutation() {
        // Voxel x along P, y along I, z along R.
        let o = Orientation::from_columns(
            [[0.0, 0.0, 2.0], [-1.0, 0.0, 0.0], [0.0, -3.0, 0.0]],
            [1.0, 2.0, 3.0],
        )
        .unwrap();
        assert_eq!(o.to_volume([0.0, 0.0, 1.0]), [0.0, -1.0, 0.0]);
        assert_eq!(o.to_volume([1.0, 0.0, 0.0]), [0.0, 0.0, 1.0]);
        // Reordered to R, A, S: x→1 flipped, y→2 flipped, z→0.
        let p = o.permuted([1, 2, 0], [true, true, false], [4, 5, 6], [1.0, 1.0, 1.0]);
        assert_eq!(p.direction, Orientation::IDENTITY.direction);
        assert_eq!(p.origin, [1.0, 2.0 - 3.0, 3.0 - 4.0]);
        assert!(Orientation::from_columns([[0.0; 3]; 3], [0.0; 3]).is_none());
    }
}
