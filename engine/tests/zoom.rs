//! `--zoom`: the zero-padded finish ([`fvr_engine::image::zoom`]) samples
//! the same projection `F` times as densely. Every `F`-th pixel of the
//! zoomed image is the unzoomed image's pixel at the same point, to within
//! the rounding of two transforms of different sizes.

use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_core::volume::GridOversampling;
use fvr_engine::spectrum::Precision;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_engine::volume::Volume;
use fvr_engine::{Renderer, Settings};

fn volume(dims: [usize; 3], spacing: [f64; 3]) -> Volume {
    // Gaussians of at least 4 voxels' width: band-limited well inside the grid.
    let mixture = GaussianMixture::random(7, dims[0].max(dims[1]).max(dims[2]), 4);
    sample(&mixture, dims).with_spacing(spacing).unwrap()
}

fn settings(grid: GridOversampling, precision: Precision) -> Settings {
    Settings {
        filter: Some(FilterKind::Kb4),
        oversample: Some(grid),
        precision: Some(precision),
        ..Settings::default()
    }
}

fn views() -> Vec<View> {
    [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.3, 0.0],
        [1.0, 0.3, 0.2],
        [-0.4, 0.2, 1.0],
    ]
    .into_iter()
    .map(View::along)
    .chain([View {
        dir: [0.0, 0.0, 1.0],
        up: [0.0, 1.0, 0.0],
    }])
    .collect()
}

/// The largest `|zoomed(F·col, F·row) − plain(col, row)|` over the image,
/// relative to the plain image's largest magnitude.
fn coinciding_error(renderer: &Renderer, view: &View, zoom: usize) -> f64 {
    let (plain, _) = renderer.render(view, None).unwrap();
    let (zoomed, _) = renderer.render_zoomed(view, None, zoom).unwrap();
    assert_eq!(zoomed.width, zoom * plain.width);
    assert_eq!(zoomed.height, zoom * plain.height);
    let peak = plain.data.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(peak > 0.0);
    let mut worst = 0.0f64;
    for row in 0..plain.height {
        for col in 0..plain.width {
            let p = plain.data[row * plain.width + col];
            let z = zoomed.data[zoom * row * zoomed.width + zoom * col];
            worst = worst.max((p - z).abs());
        }
    }
    worst / peak
}

/// The tolerance: both images are the same `n²` terms summed by DHTs whose
/// rounding grows as `ε·log₂(side²)` relative to the image's scale (the
/// row and column passes of `log₂ side` butterfly stages each), for the
/// `n`-side and the `F·n`-side transform; a factor 2 covers the twiddles'
/// own rounding and the Hao–Bracewell step. (Measured: at most 2.4e-7 in
/// f32 and 6.9e-16 in f64, about 2ε, against 2.2e-6 and 4e-15 here; power-of-two
/// zooms of power-of-two sides agree bit for bit, their twiddles nesting.)
fn tolerance(eps: f64, n: usize, zoom: usize) -> f64 {
    let log = |side: usize| 2.0 * (side as f64).log2();
    2.0 * eps * (log(n) + log(n * zoom))
}

#[test]
fn every_fth_pixel_is_the_plain_image() {
    // Odd and even sides: sub-pixel shifts on some axes, none on others.
    let cases = [
        (
            [32, 32, 32],
            GridOversampling::X1,
            Precision::F32,
            f32::EPSILON as f64,
        ),
        (
            [31, 32, 33],
            GridOversampling::X2,
            Precision::F64,
            f64::EPSILON,
        ),
        (
            [31, 30, 29],
            GridOversampling::X1_5,
            Precision::F32,
            f32::EPSILON as f64,
        ),
    ];
    for (dims, grid, precision, eps) in cases {
        let renderer = Renderer::new(&volume(dims, [1.0; 3]), settings(grid, precision)).unwrap();
        let n = renderer.n();
        for zoom in [2, 3, 4] {
            for (v, view) in views().iter().enumerate() {
                let err = coinciding_error(&renderer, view, zoom);
                let tol = tolerance(eps, n, zoom);
                println!("{dims:?} n={n} zoom {zoom} view {v}: {err:.3e} (tolerance {tol:.3e})");
                assert!(
                    err <= tol,
                    "{dims:?} zoom {zoom} view {v}: {err:e} > {tol:e}"
                );
            }
        }
    }
}

/// Physical units: anisotropic voxels and a pixel size of their own; the
/// zoomed sampling's pixel is the plain one's divided by the zoom.
#[test]
fn physical_units_and_the_pixel_size() {
    let renderer = Renderer::new(
        &volume([32, 28, 24], [0.8, 0.8, 1.3]),
        settings(GridOversampling::X1, Precision::F32),
    )
    .unwrap();
    let p = renderer.sampling().pixel_size();
    assert_eq!(renderer.zoomed_sampling(4).unwrap().pixel_size(), p / 4.0);
    assert_eq!(renderer.zoomed_sampling(1).unwrap(), *renderer.sampling());
    for view in views() {
        let err = coinciding_error(&renderer, &view, 2);
        assert!(
            err <= tolerance(f32::EPSILON as f64, renderer.n(), 2),
            "{err:e}"
        );
    }
}

/// Factors the transforms do not serve, and scenes the zoom does not
/// render, are refused by name.
#[test]
fn refused_zooms_and_scenes() {
    let cube = volume([16, 16, 16], [1.0; 3]);
    let renderer = Renderer::new(&cube, Settings::default()).unwrap();
    let view = View::along([1.0, 0.0, 0.0]);
    for bad in [0, 7, 65] {
        let e = renderer.render_zoomed(&view, None, bad).unwrap_err();
        assert!(e.to_string().contains("--zoom"), "{bad}: {e}");
    }
    let preview = Settings {
        preview_level: 1,
        ..Settings::default()
    };
    let e = Renderer::new(&cube, preview)
        .unwrap()
        .render_zoomed(&view, None, 2)
        .unwrap_err();
    assert!(e.to_string().contains("preview"), "{e}");
}
