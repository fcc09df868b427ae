//! Progressive previews: the level-L image is the full-resolution
//! projection low-passed to the central (n/2^L)² frequencies and sampled
//! every 2^L voxels.

use fvr_core::dht::signed_index;
use fvr_core::filter::{FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_core::image::{aux_len, finish, placement, Crop};
use fvr_core::render::{max_level, preview_size, render, Buffers, Request, Source};
use fvr_core::slice::extract_slice;
use fvr_host::reference::snr_db;
use fvr_tests::mixture_spectrum;

#[test]
fn preview_is_the_low_passed_projection_sampled_at_its_pitch() {
    let n = 64;
    let (owned, filter) = mixture_spectrum::<f64, f64>((6, n, 8), [n; 3], FilterKind::Kb4, 1);
    let spec = owned.view();
    let kernel = KernelTable::<f64>::new(filter);
    fvr_tests::twiddles!(n; tw: f64);
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
        render(
            &Source::new(&spec, &kernel, &tw),
            &Request {
                level,
                ..Request::new(view, w, h)
            },
            Buffers::new(&mut grid, &mut aux, &mut out),
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
        finish(
            &mut full,
            n,
            &Crop::new(place, 1.0 / spec.scale(), n, n),
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
    // A level beyond max_level, and an image larger than the level's grid.
    for (level, side) in [(6, 1), (1, 33)] {
        let request = Request {
            level,
            ..Request::new(view, side, side)
        };
        let mut out = vec![0.0; side * side];
        let buffers = Buffers::new(&mut big, &mut aux, &mut out);
        assert!(render(&Source::new(&spec, &kernel, &tw), &request, buffers).is_err());
    }
}
