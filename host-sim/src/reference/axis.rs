//! The exact projection of the band-limited interpolant for a view along a
//! grid axis whose pixels fall on voxels: the sum of the voxels on each line.
//!
//! The band-limited interpolant through the samples integrates, along an
//! axis and through a voxel column, to the sum of that column's samples
//! (each sinc integrates to 1); a pixel beyond the volume sees nothing.

use fvr_core::geometry::{center, View};

use fvr_engine::volume::Volume;

/// The exact `width × height` X-ray image of `volume` along `view`, or
/// `None` unless the view is along a grid axis (right and up along axes,
/// within 1e-12) and every pixel centre falls on integer voxel coordinates
/// (even sizes across the view, even image sizes, or odd with odd).
///
/// # Errors
/// Bad view vectors.
pub fn axis_projection(
    volume: &Volume,
    view: &View,
    width: usize,
    height: usize,
) -> Result<Option<Vec<f64>>, fvr_core::Error> {
    let frame = view.frame()?;
    let axis_of = |v: [f64; 3]| {
        (0..3).find(|&a| {
            (v[a].abs() - 1.0).abs() < 1e-12 && v.iter().map(|x| x * x).sum::<f64>() < 1.0 + 1e-12
        })
    };
    let (Some(d), Some(r), Some(u)) = (axis_of(frame.dir), axis_of(frame.right), axis_of(frame.up))
    else {
        return Ok(None);
    };
    let dims = volume.dims;
    let c = center(dims);
    let mut out = Vec::with_capacity(width * height);
    for row in 0..height {
        for col in 0..width {
            let p = frame.pixel_position(c, width, height, col as f64, row as f64);
            if [p[r], p[u]].iter().any(|x| x.fract() != 0.0) {
                return Ok(None);
            }
            let (i, j) = (p[r] as i64, p[u] as i64);
            if !(0..dims[r] as i64).contains(&i) || !(0..dims[u] as i64).contains(&j) {
                out.push(0.0);
                continue;
            }
            let mut idx = [0usize; 3];
            idx[r] = i as usize;
            idx[u] = j as usize;
            let mut sum = 0.0;
            for k in 0..dims[d] {
                idx[d] = k;
                sum += volume.get(idx[0], idx[1], idx[2]) as f64;
            }
            out.push(sum);
        }
    }
    Ok(Some(out))
}
