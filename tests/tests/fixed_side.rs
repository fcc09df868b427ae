//! A spectrum whose side is fixed at compile time (`Spectrum::with_side`,
//! the firmware's fast path) renders the same image, bit for bit, as the
//! same spectrum with its side known at run time; a wrong side is an error.

use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind, KernelTable};
use fvr_core::geometry::View;
use fvr_core::image::{aux_len, grid_len};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::spectrum::{CubeSide, Spectrum};
use fvr_core::Error;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_tests::mixture_spectrum;
use half::f16;

const N: usize = 32;

fn render_view<Z: CubeSide>(spec: &Spectrum<'_, f16, Z>, filter: Filter, view: &View) -> Vec<f32> {
    let n = spec.n();
    let kernel = KernelTable::<f32>::new(filter);
    let mut tw_buf = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n).unwrap();
    let (mut grid, mut aux) = (vec![0.0f32; grid_len(n)], vec![0.0f32; aux_len(n)]);
    let mut out = vec![0.0f32; n * n];
    render(
        &Source::new(spec, &kernel, &tw),
        &Request::new(*view, n, n),
        Buffers::new(&mut grid, &mut aux, &mut out),
    )
    .unwrap();
    out
}

#[test]
fn a_compile_time_side_renders_the_run_time_image_bit_for_bit() {
    let volume = sample(&GaussianMixture::random(23, N, 5), [N; 3]);
    // Views whose slices wrap around the cube on every axis (oblique) and
    // along one axis only, so both tap paths (contiguous and wrapped) run.
    let views = [
        View::along([1.0, 0.3, 0.2]),
        View::along([0.2, -1.0, 0.7]),
        View::along([1.0, 1.0, 1.0]),
        View::along([1.0, 0.0, 0.0]),
    ];
    for kind in [
        FilterKind::Nearest,
        FilterKind::Linear,
        FilterKind::Kb3,
        FilterKind::Kb4,
        FilterKind::Kb6,
    ] {
        let filter = Filter::new(kind, 1).unwrap();
        let owned = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
        for view in &views {
            let runtime = render_view(&owned.view(), filter, view);
            let fixed = render_view(&owned.view().with_side::<N>().unwrap(), filter, view);
            let same = runtime
                .iter()
                .zip(&fixed)
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "{kind:?} along {view:?}: the images differ");
            // Not trivially equal: a view of the phantom.
            assert!(runtime.iter().any(|&v| v > 1.0), "{kind:?}: an empty image");
        }
    }
}

#[test]
fn a_wrong_compile_time_side_is_an_error_naming_both_sides() {
    let (owned, _) = mixture_spectrum::<f16, f32>((3, N, 2), [N; 3], FilterKind::Kb3, 1);
    match owned.view().with_side::<64>() {
        Err(Error::LengthMismatch {
            what,
            expected,
            got,
        }) => {
            assert!(what.contains("spectrum side"), "{what}");
            assert_eq!((expected, got), (64, N));
        }
        other => panic!("expected a side mismatch, got {other:?}"),
    }
}
