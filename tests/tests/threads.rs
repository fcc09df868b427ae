//! Row-parallel extraction on the host: the same image, bit for bit,
//! whatever the number of threads or the split of rows.

use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_core::slice::{extract_slice, extract_slice_rows};
use fvr_core::Error;
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_tests::mixture_spectrum;
use half::f16;

#[test]
fn threaded_views_equal_the_single_threaded_view_bit_for_bit() {
    let n = 64;
    let mixture = GaussianMixture::random(11, n, 6);
    let volume = sample(&mixture, [n; 3]);
    for kind in [FilterKind::Linear, FilterKind::Kb3, FilterKind::Kb6] {
        let filter = Filter::new(kind, 1).unwrap();
        let spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        let view = View::along([1.0, 0.3, 0.2]);
        let render = |threads: usize| {
            let mut renderer = ViewRenderer::<f32>::new(n, filter).with_threads(threads);
            let mut out = vec![0.0f32; n * n];
            renderer.render_into(&spec, &view, n, n, &mut out).unwrap();
            out
        };
        let single = render(1);
        for threads in [2, 3, 4, 8] {
            let image = render(threads);
            let same = single
                .iter()
                .zip(&image)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{kind:?} on {threads} threads differs");
        }
        // Not trivially equal: a view of the phantom, all finite.
        assert!(single.iter().all(|v| v.is_finite()));
        assert!(single.iter().any(|&v| v > 1.0), "{kind:?}: an empty image");
    }
}

#[test]
fn row_blocks_in_any_split_equal_the_whole_slice() {
    let n = 32;
    let (spec, filter) = mixture_spectrum::<f16, f32>((5, n, 4), [n; 3], FilterKind::Kb4, 1);
    let spec = spec.view();
    let kernel = KernelTable::<f32>::new(filter);
    let frame = View::along([0.2, -1.0, 0.7]).frame().unwrap();
    let mut whole = vec![0.0f32; n * n];
    extract_slice(&spec, &kernel, &frame, &mut whole);
    for split in [1, 5, 16, 31] {
        let mut pieces = vec![0.0f32; n * n];
        let (head, tail) = pieces.split_at_mut(split * n);
        extract_slice_rows(&spec, &kernel, &frame.slice_axes(), 0, head).unwrap();
        extract_slice_rows(&spec, &kernel, &frame.slice_axes(), split, tail).unwrap();
        assert!(
            whole
                .iter()
                .zip(&pieces)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "split at row {split}"
        );
    }
    // Ragged or out-of-range blocks are refused.
    let mut ragged = vec![0.0f32; n * 3 + 1];
    assert!(matches!(
        extract_slice_rows(&spec, &kernel, &frame.slice_axes(), 0, &mut ragged),
        Err(Error::LengthMismatch { .. })
    ));
    let mut beyond = vec![0.0f32; n * 4];
    assert!(matches!(
        extract_slice_rows(&spec, &kernel, &frame.slice_axes(), n - 2, &mut beyond),
        Err(Error::LengthMismatch { .. })
    ));
}
