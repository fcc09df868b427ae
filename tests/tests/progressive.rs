//! Progressive previews: the level-L image is the full-resolution
//! projection low-passed to the central (n/2^L)² frequencies and sampled
//! every 2^L voxels.

use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_core::progressive::{max_level, preview_size, render_level};
use fvr_core::render::{aux_len, extract_slice, finish_projection, placement, signed_index};
use fvr_host::reference::snr_db;
use fvr_host::render::spectrum::OwnedSpectrum;
use fvr_host::sources::phantom::{sample, GaussianMixture};

#[test]
fn preview_is_the_low_passed_projection_sampled_at_its_pitch() {
    let n = 64;
    let volume = sample(&GaussianMixture::random(6, n, 8), [n; 3]);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let owned = OwnedSpectrum::<f64>::prepare::<f64>(&volume, filter).unwrap();
    let spec = owned.view();
    let kernel = KernelTable::<f64>::new(filter);
    let mut tw_buf = vec![0.0; Twiddles::<f64>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n).unwrap();
    let view = View::along([1.0, 0.35, -0.25]);
    let frame = view.frame().unwrap();
    assert_eq!(max_level(n), 5);
    for level in 0..=3u32 {
        let p = 1usize << level;
        let m = n >> level;
        let (w, h) = preview_size(n, n, level);
        assert_eq!((w, h), (m, m));
        let mut grid = vec![0.0; m * m];
        let mut aux = vec![0.0; aux_len(m)];
        let mut out = vec![0.0; w * h];
        render_level(
            &spec, &kernel, &view, w, h, level, &tw, &mut grid, &mut aux, &mut out,
        )
        .unwrap();
        // Reference: the full slice with the outer frequencies zeroed.
        let mut full = vec![0.0; n * n];
        extract_slice(&spec, &kernel, &frame, &mut full);
        let half = (m / 2) as i64;
        for iy in 0..n {
            for ix in 0..n {
                let (kx, ky) = (signed_index(ix, n), signed_index(iy, n));
                if kx < -half || kx >= half || ky < -half || ky >= half {
                    full[iy * n + ix] = 0.0;
                }
            }
        }
        let mut image = vec![0.0; n * n];
        let mut aux_full = vec![0.0; aux_len(n)];
        let place = placement(spec.dims(), &frame, n, n);
        finish_projection(
            &mut full,
            n,
            &place,
            1.0 / spec.scale(),
            n,
            n,
            &tw,
            &mut aux_full,
            &mut image,
        )
        .unwrap();
        let decimated: Vec<f64> = (0..h)
            .flat_map(|r| (0..w).map(move |c| (r, c)))
            .map(|(r, c)| image[r * p * n + c * p])
            .collect();
        let snr = snr_db(&decimated, &out);
        assert!(snr >= 250.0, "level {level}: {snr:.1} dB");
    }
    let mut big = vec![0.0; n * n];
    let mut aux = vec![0.0; aux_len(n)];
    assert!(render_level(
        &spec,
        &kernel,
        &view,
        1,
        1,
        6,
        &tw,
        &mut big,
        &mut aux,
        &mut [0.0]
    )
    .is_err());
    assert!(render_level(
        &spec,
        &kernel,
        &view,
        33,
        33,
        1,
        &tw,
        &mut big,
        &mut aux,
        &mut vec![0.0; 33 * 33]
    )
    .is_err());
}
