//! The Utah teapot as a built-in volume, `teapot[@N]`: Newell's 32 bicubic
//! Bézier patches voxelized into a solid with anti-aliased edges.
//!
//! # Provenance
//! Martin Newell's teapot (University of Utah, 1975): 306 control points and
//! 32 bicubic Bézier patches — rim (patches 1–4), body (5–12), handle
//! (13–16), spout (17–20), lid (21–28) and bottom (29–32), z up, spout
//! towards +x. The numbers are the classic, widely republished data set
//! (see F. C. Crow, "The Origins of the Teapot", IEEE Computer Graphics and
//! Applications 7(1), 1987); they are factual data, free of copyright, and
//! are tabulated below in their usual order with one-based indices.
//!
//! # Voxelization
//! The surface is not closed: the lid and the body are separate shells,
//! the handle and the spout are tubes whose open ends sit on the body, and
//! the lid's rim (radius 1.3) does not meet the body's (radius 1.4). So the
//! patches are split into four parts — body (rim, body and bottom, closed
//! except for the lid opening), lid, handle and spout — and each part is
//! filled by itself. Each part's open edges (the lid opening at z = 2.4,
//! the tube ends) lie in planes that contain the y axis, so a ray along y
//! crosses each part's surface an even number of times: it is inside the
//! part between the 1st and 2nd crossing, the 3rd and 4th, and so on
//! (parity). The solid is the union of the four parts: the lid sits on a
//! body filled up to z = 2.4, and the tube ends are buried in the body.
//!
//! The patches are tessellated into triangles; rays run along y through
//! S × S sub-samples of each voxel's (x, z) footprint, with a half-open
//! (top-left) fill rule so that a ray through a shared edge counts it once;
//! along each ray the covered length inside each voxel is exact. A voxel's
//! value is its covered volume fraction in [0, 1], a box-filtered (and so
//! anti-aliased) occupancy; one pass of the binomial filter [1, 2, 1]/4 per
//! axis then smooths the edges over about two voxels, so that the
//! band-limited interpolant of the samples does not ring at the surface.

use fvr_engine::volume::Volume;

/// Side of `teapot` when no `@N` is given.
pub const DEFAULT_TEAPOT_SIZE: usize = 128;

/// Sub-samples per voxel side across the rays (S above).
pub const TEAPOT_SUPERSAMPLING: usize = 4;

/// The half-diagonal of the teapot's bounding box spans this fraction of
/// the volume's side, so that every view of it stays inside the volume's
/// inscribed sphere.
pub const TEAPOT_RADIUS_FRACTION: f64 = 0.45;

/// Patches of each part, as half-open index ranges `(start, end)` of
/// [`TeapotTable::patches`]: body (rim, body, bottom), handle, spout, lid.
pub const TEAPOT_PARTS: [(&str, &[(usize, usize)]); 4] = [
    ("body", &[(0, 12), (28, 32)]),
    ("handle", &[(12, 16)]),
    ("spout", &[(16, 20)]),
    ("lid", &[(20, 28)]),
];

/// Newell's data set in the classic text layout: the patch count, then a
/// line of 16 one-based point indices a patch (4 rows of 4 control points,
/// row by row), then the point count, then a line `x,y,z` a point, z up,
/// spout towards +x, in the data set's order (see the module's
/// provenance).
const TEAPOT_TEXT: &str = include_str!("teapot.txt");

/// The teapot's control points and patches.
#[derive(Debug)]
pub struct TeapotTable {
    /// The 306 control points `(x, y, z)`.
    pub points: Vec<[f64; 3]>,
    /// The 32 patches, each 16 one-based indices into `points`.
    pub patches: Vec<[u16; 16]>,
}

/// The table of [`TEAPOT_TEXT`], parsed on first use. The text is part of
/// the program, and a test parses it; a malformed table is a build defect.
pub fn teapot_table() -> &'static TeapotTable {
    static TABLE: std::sync::OnceLock<TeapotTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| parse_table(TEAPOT_TEXT).expect("the built-in teapot table parses"))
}

/// `count` rows of `N` comma-separated numbers after a line holding
/// `count`, from `lines`.
fn parse_rows<const N: usize, T: std::str::FromStr>(
    lines: &mut std::str::Lines<'_>,
) -> Result<Vec<[T; N]>, String> {
    let count: usize = lines
        .next()
        .and_then(|l| l.trim().parse().ok())
        .ok_or("missing row count")?;
    (0..count)
        .map(|i| {
            let line = lines.next().ok_or(format!("row {i} missing"))?;
            let values: Vec<T> = line
                .split(',')
                .map(|v| v.trim().parse().map_err(|_| format!("row {i}: `{line}`")))
                .collect::<Result<_, _>>()?;
            <[T; N]>::try_from(values).map_err(|_| format!("row {i}: not {N} values"))
        })
        .collect()
}

/// The patches and then the points of a text in [`TEAPOT_TEXT`]'s layout,
/// every index checked against the points.
fn parse_table(text: &str) -> Result<TeapotTable, String> {
    let mut lines = text.lines();
    let patches: Vec<[u16; 16]> = parse_rows(&mut lines)?;
    let points = parse_rows(&mut lines)?;
    if let Some(bad) = patches
        .iter()
        .flatten()
        .find(|&&i| i == 0 || i as usize > points.len())
    {
        return Err(format!("point index {bad} out of range"));
    }
    Ok(TeapotTable { points, patches })
}

/// The control points of patch `p`, `[row][column]`.
fn control_points(p: usize) -> [[[f64; 3]; 4]; 4] {
    let table = teapot_table();
    std::array::from_fn(|r| {
        std::array::from_fn(|c| table.points[table.patches[p][4 * r + c] as usize - 1])
    })
}

/// Cubic Bernstein weights at `t`.
fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
}

/// The point of patch `cp` at parameters `(u, v)` (u along rows, v along
/// columns).
fn patch_point(cp: &[[[f64; 3]; 4]; 4], u: f64, v: f64) -> [f64; 3] {
    let (bu, bv) = (bernstein(u), bernstein(v));
    let mut p = [0.0; 3];
    for r in 0..4 {
        for c in 0..4 {
            let w = bu[r] * bv[c];
            for a in 0..3 {
                p[a] += w * cp[r][c][a];
            }
        }
    }
    p
}

/// Patch `p` evaluated on an `(m + 1) × (m + 1)` grid of parameters.
fn patch_grid(p: usize, m: usize) -> Vec<[f64; 3]> {
    let cp = control_points(p);
    let mut grid = Vec::with_capacity((m + 1) * (m + 1));
    for i in 0..=m {
        for j in 0..=m {
            grid.push(patch_point(&cp, i as f64 / m as f64, j as f64 / m as f64));
        }
    }
    grid
}

/// Triangles of the patches in `ranges`, each patch cut into `m × m` quads.
fn tessellate(ranges: &[(usize, usize)], m: usize) -> Vec<[[f64; 3]; 3]> {
    let mut triangles = Vec::new();
    for p in ranges.iter().flat_map(|&(start, end)| start..end) {
        let g = patch_grid(p, m);
        let at = |i: usize, j: usize| g[i * (m + 1) + j];
        for i in 0..m {
            for j in 0..m {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
    }
    triangles
}

/// The bounding box `(min, max)` of the teapot's surface (not of its
/// control points), from each patch evaluated on a 65 × 65 grid.
pub fn teapot_surface_bounds() -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in 0..teapot_table().patches.len() {
        for q in patch_grid(p, 64) {
            for a in 0..3 {
                lo[a] = lo[a].min(q[a]);
                hi[a] = hi[a].max(q[a]);
            }
        }
    }
    (lo, hi)
}

/// The teapot voxelized into an `n`³ volume, with how many rays crossed a
/// part's surface an odd number of times (each such ray is left empty for
/// that part; a closed part gives none).
#[derive(Debug)]
pub struct TeapotVoxels {
    /// Covered volume fraction per voxel, smoothed (see the module).
    pub volume: Volume,
    /// Rays with an odd number of crossings of one part.
    pub odd_rays: usize,
    /// Scale from teapot units to voxels.
    pub voxels_per_unit: f64,
    /// Where the teapot's origin (the centre of its bottom) lands, in voxels.
    pub origin: [f64; 3],
}

/// Map teapot units to voxel coordinates of an `n`³ volume: the surface's
/// bounding box is centred, its half-diagonal spans
/// [`TEAPOT_RADIUS_FRACTION`]` · n`.
fn placement(n: usize) -> (f64, [f64; 3]) {
    let (lo, hi) = teapot_surface_bounds();
    let half_diagonal = (0..3)
        .map(|a| (hi[a] - lo[a]) * (hi[a] - lo[a]))
        .sum::<f64>()
        .sqrt()
        / 2.0;
    let scale = TEAPOT_RADIUS_FRACTION * n as f64 / half_diagonal;
    let origin = std::array::from_fn(|a| n as f64 / 2.0 - scale * (lo[a] + hi[a]) / 2.0);
    (scale, origin)
}

/// Voxelize the teapot into an `n`³ volume (see the module for the method).
///
/// # Errors
/// `n` below 8 or above [`crate::sources::MAX_PHANTOM_SIZE`].
pub fn voxelize_teapot(n: usize) -> Result<TeapotVoxels, String> {
    if !(8..=crate::sources::MAX_PHANTOM_SIZE).contains(&n) {
        return Err(format!(
            "teapot size {n} must be from 8 to {}",
            crate::sources::MAX_PHANTOM_SIZE
        ));
    }
    let s = TEAPOT_SUPERSAMPLING;
    let (scale, origin) = placement(n);
    // About one triangle edge per voxel on the largest patches (about 1.5
    // units across), so the chords sit well within a tenth of a voxel.
    let m = ((1.5 * scale).ceil() as usize).clamp(8, 64);
    let to_voxels = |p: [f64; 3]| -> [f64; 3] { std::array::from_fn(|a| origin[a] + scale * p[a]) };
    let rows = n * s;
    // Ray (column c, row r) runs along y at x = (c + 0.5)/S − 0.5 and
    // z = (r + 0.5)/S − 0.5 in voxel units, nudged by a small irrational
    // amount so that no ray meets a vertex exactly.
    let sub = |t: usize, nudge: f64| (t as f64 + 0.5) / s as f64 - 0.5 + nudge;
    const NUDGE_X: f64 = 1.0e-7 * std::f64::consts::SQRT_2;
    const NUDGE_Z: f64 = 1.0e-7 * std::f64::consts::E;
    let mut covered = vec![0.0f64; n * n * n];
    let mut odd_rays = 0usize;
    let parts: Vec<Vec<[[f64; 3]; 3]>> = TEAPOT_PARTS
        .iter()
        .map(|(_, ranges)| {
            tessellate(ranges, m)
                .into_iter()
                .map(|t| t.map(to_voxels))
                .collect()
        })
        .collect();
    // Triangles of each part by the ray rows they span.
    let by_row: Vec<Vec<Vec<usize>>> = parts
        .iter()
        .map(|tris| {
            let mut rows_of = vec![Vec::new(); rows];
            for (t, tri) in tris.iter().enumerate() {
                let zmin = tri.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
                let zmax = tri.iter().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max);
                let first = ((zmin + 0.5) * s as f64 - 0.5).floor().max(0.0) as usize;
                let last = ((zmax + 0.5) * s as f64 - 0.5).ceil().max(0.0) as usize;
                for r in first..=last.min(rows - 1) {
                    rows_of[r].push(t);
                }
            }
            rows_of
        })
        .collect();
    let mut hits: Vec<Vec<Vec<f64>>> = vec![vec![Vec::new(); rows]; parts.len()];
    let mut spans: Vec<(f64, f64)> = Vec::new();
    let weight = 1.0 / (s * s) as f64;
    for r in 0..rows {
        let z = sub(r, NUDGE_Z);
        for (part, tris) in parts.iter().enumerate() {
            for column in hits[part].iter_mut() {
                column.clear();
            }
            for &t in &by_row[part][r] {
                scan_triangle(&tris[t], z, rows, s, NUDGE_X, &mut hits[part]);
            }
        }
        let k = r / s;
        for c in 0..rows {
            spans.clear();
            for part in hits.iter_mut() {
                let column = &mut part[c];
                if column.len() % 2 == 1 {
                    odd_rays += 1;
                    continue;
                }
                column.sort_by(f64::total_cmp);
                spans.extend(column.chunks_exact(2).map(|p| (p[0], p[1])));
            }
            spans.sort_by(|a, b| a.0.total_cmp(&b.0));
            let i = c / s;
            let mut current: Option<(f64, f64)> = None;
            for &(a, b) in spans.iter() {
                match current {
                    Some((ca, cb)) if a <= cb => current = Some((ca, cb.max(b))),
                    Some(done) => {
                        add_span(&mut covered, n, i, k, done, weight);
                        current = Some((a, b));
                    }
                    None => current = Some((a, b)),
                }
            }
            if let Some(done) = current {
                add_span(&mut covered, n, i, k, done, weight);
            }
        }
    }
    let smoothed = binomial_smooth(&covered, n);
    Ok(TeapotVoxels {
        volume: Volume::new([n; 3], smoothed.into_iter().map(|v| v as f32).collect()),
        odd_rays,
        voxels_per_unit: scale,
        origin,
    })
}

/// Record where the rays of row `z` cross triangle `tri` (voxel units): the
/// rays whose x lies in the triangle's projection on the (x, z) plane, by a
/// half-open rule on both axes, get the y of the crossing.
fn scan_triangle(
    tri: &[[f64; 3]; 3],
    z: f64,
    columns: usize,
    s: usize,
    nudge_x: f64,
    hits: &mut [Vec<f64>],
) {
    // Where the line z = const crosses the triangle's edges (half-open in z).
    let mut xs = [0.0; 2];
    let mut found = 0;
    for e in 0..3 {
        let (p, q) = (tri[e], tri[(e + 1) % 3]);
        let (lo, hi) = if p[2] <= q[2] { (p, q) } else { (q, p) };
        if z >= lo[2] && z < hi[2] {
            if found == 2 {
                return;
            }
            xs[found] = lo[0] + (z - lo[2]) / (hi[2] - lo[2]) * (hi[0] - lo[0]);
            found += 1;
        }
    }
    if found != 2 {
        return;
    }
    let (x0, x1) = (xs[0].min(xs[1]), xs[0].max(xs[1]));
    // The plane of the triangle: y = y(x, z), from its normal.
    let u: [f64; 3] = std::array::from_fn(|a| tri[1][a] - tri[0][a]);
    let v: [f64; 3] = std::array::from_fn(|a| tri[2][a] - tri[0][a]);
    let normal = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    if normal[1] == 0.0 {
        return;
    }
    // Columns c with x0 <= x_c < x1, x_c = (c + 0.5)/S − 0.5 + nudge.
    let first = ((x0 - nudge_x + 0.5) * s as f64 - 0.5).ceil().max(0.0) as usize;
    for c in first..columns {
        let x = (c as f64 + 0.5) / s as f64 - 0.5 + nudge_x;
        if x >= x1 {
            break;
        }
        if x < x0 {
            continue;
        }
        let y = tri[0][1] - (normal[0] * (x - tri[0][0]) + normal[2] * (z - tri[0][2])) / normal[1];
        hits[c].push(y);
    }
}

/// Add the covered length of `[a, b]` (voxel units along y) to each voxel
/// `(i, j, k)` it overlaps, voxel j spanning `[j − 0.5, j + 0.5]`.
fn add_span(covered: &mut [f64], n: usize, i: usize, k: usize, (a, b): (f64, f64), w: f64) {
    if i >= n || k >= n {
        return;
    }
    let first = (a + 0.5).floor().max(0.0) as usize;
    let last = ((b + 0.5).floor().max(0.0) as usize).min(n - 1);
    for j in first..=last {
        let overlap = b.min(j as f64 + 0.5) - a.max(j as f64 - 0.5);
        if overlap > 0.0 {
            covered[i + n * (j + n * k)] += w * overlap;
        }
    }
}

/// One pass of [1, 2, 1]/4 along each axis (zero outside the volume).
fn binomial_smooth(data: &[f64], n: usize) -> Vec<f64> {
    let mut a = data.to_vec();
    let mut b = vec![0.0; a.len()];
    for stride in [1, n, n * n] {
        for idx in 0..a.len() {
            let pos = (idx / stride) % n;
            let before = if pos > 0 { a[idx - stride] } else { 0.0 };
            let after = if pos + 1 < n { a[idx + stride] } else { 0.0 };
            b[idx] = 0.25 * before + 0.5 * a[idx] + 0.25 * after;
        }
        std::mem::swap(&mut a, &mut b);
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_complete_and_patches_share_their_edges() {
        let TeapotTable { points, patches } = teapot_table();
        assert_eq!((points.len(), patches.len()), (306, 32));
        // Every control point is used, and every index is in range.
        let mut used = [false; 306];
        for &patch in patches {
            for i in patch {
                assert!((1..=306).contains(&i));
                used[i as usize - 1] = true;
            }
        }
        // The data set's four points next to the lid's pole, 0.002 off the
        // axis, are unused (the patches meet at the pole point itself).
        let unused: Vec<usize> = (0..306).filter(|&i| !used[i]).collect();
        assert_eq!(unused.len(), 4, "{unused:?}");
        for i in unused {
            let [x, y, z] = points[i];
            assert!(x.hypot(y) == 0.002 && z == 3.15, "{i}");
        }
        // The body's four quarters close up: the last column of each quarter is
        // the first column of the next.
        for quarter in [0, 4, 8, 28] {
            for q in 0..4 {
                let a = patches[quarter + q];
                let b = patches[quarter + (q + 1) % 4];
                for r in 0..4 {
                    assert_eq!(a[4 * r + 3], b[4 * r], "patch {}", quarter + q);
                }
            }
        }
    }

    #[test]
    fn surface_is_mirror_symmetric_in_y() {
        // Every control point has its mirror image (x, −y, z) in the table.
        let points = &teapot_table().points;
        for p in points {
            let mirror = [p[0], -p[1], p[2]];
            assert!(points.contains(&mirror), "{p:?}");
        }
    }

    #[test]
    fn surface_bounds_match_the_classic_proportions() {
        let (lo, hi) = teapot_surface_bounds();
        // Handle at x = −3, spout tip near 3.43; 4 deep; bottom 0, knob 3.15.
        assert!((lo[0] + 3.0).abs() < 1e-9, "{lo:?}");
        assert!(hi[0] > 3.4 && hi[0] < 3.525, "{hi:?}");
        assert!((lo[1] + 2.0).abs() < 1e-9 && (hi[1] - 2.0).abs() < 1e-9);
        assert!(lo[2].abs() < 1e-9 && (hi[2] - 3.15).abs() < 1e-9);
    }

    /// Value at the voxel nearest to teapot point `p`.
    fn at(t: &TeapotVoxels, p: [f64; 3]) -> f32 {
        let [i, j, k] =
            std::array::from_fn(|a| (t.origin[a] + t.voxels_per_unit * p[a]).round() as usize);
        t.volume.get(i, j, k)
    }

    #[test]
    fn voxelization_is_deterministic_closed_and_symmetric() {
        let n = 128;
        let t = voxelize_teapot(n).unwrap();
        assert_eq!(
            t.odd_rays, 0,
            "a part leaks: rays crossed it an odd number of times"
        );
        assert_eq!(t.volume.data, voxelize_teapot(n).unwrap().volume.data);
        assert!(t
            .volume
            .data
            .iter()
            .all(|&v| (0.0..=1.0 + 1e-6).contains(&v)));
        // Solid inside the body, the lid's dome, the handle and the spout;
        // empty in the handle's hole, over the lid's rim and above the knob.
        for inside in [
            [0.0, 0.0, 1.2],
            [0.9, 0.5, 0.5],
            [0.0, 0.0, 2.5],
            [-2.85, 0.0, 1.7],
            [2.3, 0.0, 1.3],
        ] {
            assert!(at(&t, inside) > 0.99, "{inside:?}: {}", at(&t, inside));
        }
        for outside in [
            [-2.35, 0.0, 1.5],
            [0.0, 0.0, 3.5],
            [0.0, 2.4, 1.0],
            [2.4, 0.0, 0.3],
        ] {
            assert!(at(&t, outside) < 0.01, "{outside:?}: {}", at(&t, outside));
        }
        // Mirror symmetry of the data in y maps voxel j to n - j, up to the
        // triangulation: a quad's diagonal mirrors to the other diagonal,
        // and the two differ by the quad's non-planarity (about 1e-3 of a
        // voxel here, measured 1.4e-3 of full occupancy).
        let mut worst = 0.0f32;
        for k in 0..n {
            for j in 1..n {
                for i in 0..n {
                    worst = worst.max((t.volume.get(i, j, k) - t.volume.get(i, n - j, k)).abs());
                }
            }
        }
        assert!(worst < 5e-3, "asymmetry {worst}");
    }

    #[test]
    fn voxelized_proportions_and_volume_converge() {
        let mut volumes = Vec::new();
        for n in [48, 96] {
            let t = voxelize_teapot(n).unwrap();
            assert_eq!(t.odd_rays, 0, "n = {n}");
            // The extent of the voxels at least 5% full along each axis, in units.
            let mut lo = [usize::MAX; 3];
            let mut hi = [0usize; 3];
            for k in 0..n {
                for j in 0..n {
                    for i in 0..n {
                        if t.volume.get(i, j, k) >= 0.05 {
                            for (a, x) in [i, j, k].into_iter().enumerate() {
                                lo[a] = lo[a].min(x);
                                hi[a] = hi[a].max(x);
                            }
                        }
                    }
                }
            }
            let extent: Vec<f64> = (0..3)
                .map(|a| (hi[a] - lo[a] + 1) as f64 / t.voxels_per_unit)
                .collect();
            let (blo, bhi) = teapot_surface_bounds();
            for a in 0..3 {
                let exact = bhi[a] - blo[a];
                eprintln!("n {n} axis {a}: {} against {exact}", extent[a]);
                // The box filter and the smoothing widen the edge by up to
                // 1.5 voxels at each end.
                assert!(
                    (extent[a] - exact).abs() < 3.5 / t.voxels_per_unit,
                    "n {n} axis {a}: {extent:?}"
                );
            }
            let units3 =
                t.volume.data.iter().map(|&v| v as f64).sum::<f64>() / t.voxels_per_unit.powi(3);
            eprintln!("n {n}: {units3} units^3");
            volumes.push(units3);
        }
        // A solid a little smaller than the body's bounding cylinder
        // (pi 2^2 2.4 = 30 units^3), with the lid, handle and spout added,
        // and the same at both resolutions.
        assert!(volumes[1] > 20.0 && volumes[1] < 30.0, "{volumes:?}");
        assert!(
            (volumes[0] - volumes[1]).abs() < 0.01 * volumes[1],
            "{volumes:?}"
        );
    }

    #[test]
    fn sizes_out_of_range_are_errors() {
        assert!(voxelize_teapot(4).unwrap_err().contains("from 8"));
        assert!(voxelize_teapot(1 << 20).is_err());
    }
}
