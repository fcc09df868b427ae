//! Criterion benchmarks: 2× padding against the mixed-radix grids
//! σ = 1.25 and 1.5 on real heads ([`CONFIGS`]), f16 (f32 arithmetic),
//! filter fitted to the volume: per-view time (one oblique view on all cores) and
//! preparation time. Before timing, each grid's spectrum size and its SNR
//! against the exact axis projections (voxel sums, x, y and z views) are
//! printed, so that one run gives the whole table of docs/accuracy.md.
//!
//! Volumes: `brainsmall` (embedded), and the CT head resampled to 256 when
//! `FVR_CT_HEAD` names `Cranium.inv3` (`bash scripts/fetch-ct-head.sh`).
//!
//! Run: `FVR_CT_HEAD=$(bash scripts/fetch-ct-head.sh) cargo bench -p fvr-host --bench grids`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::filter::FilterKind;
use fvr_core::geometry::View;
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::plan::{grid_filter, image_side, AXIS_VIEWS};
use fvr_engine::render::view::ViewRenderer;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::Volume;
use fvr_host::reference::axis::axis_projection;
use fvr_host::reference::snr_db;
use fvr_host::sources::datasets::load_dataset;
use half::f16;

/// Filter and grid: 2× padding with kb4, then the mixed-radix grids with
/// kb4 and, at σ = 1.25, the wider kb5 and kb6.
const CONFIGS: [(FilterKind, GridOversampling); 5] = [
    (FilterKind::Kb4, GridOversampling::X2),
    (FilterKind::Kb4, GridOversampling::X1_5),
    (FilterKind::Kb4, GridOversampling::X1_25),
    (FilterKind::Kb5, GridOversampling::X1_25),
    (FilterKind::Kb6, GridOversampling::X1_25),
];

fn volumes() -> Vec<(&'static str, Volume)> {
    let mut out = vec![(
        "brainsmall",
        load_dataset("brainsmall")
            .unwrap()
            .unwrap()
            .cropped_to_even(),
    )];
    if std::env::var_os("FVR_CT_HEAD").is_some() {
        let ct = load_dataset("ct-head").unwrap().unwrap();
        out.push((
            "ct-head@256",
            ct.resample_isotropic(256).unwrap().cropped_to_even(),
        ));
    }
    out
}

fn benches(c: &mut Criterion) {
    let view = View::along([1.0, 0.35, 0.2]);
    for (name, volume) in volumes() {
        let mut group = c.benchmark_group(format!("grids_{name}_f16"));
        group.sample_size(10);
        for (kind, grid) in CONFIGS {
            let filter = grid_filter(&volume, kind, grid, KbDesign::Auto).unwrap();
            let id = format!("{}_{}", kind.name(), grid.name());
            let spec = OwnedSpectrum::<f16>::prepare_on::<f32>(
                &volume,
                filter,
                grid.side(volume.dims).unwrap(),
            )
            .unwrap();
            let n = spec.n();
            let side = image_side(volume.dims, n).unwrap();
            let mut renderer = ViewRenderer::<f32>::new(n, filter);
            let mut out = vec![0.0f32; side * side];
            let db = AXIS_VIEWS.map(|v| {
                renderer
                    .render_into(&spec, &v, side, side, &mut out)
                    .unwrap();
                let exact = axis_projection(&volume, &v, side, side).unwrap().unwrap();
                let image: Vec<f64> = out.iter().map(|&x| x as f64).collect();
                snr_db(&exact, &image)
            });
            println!(
                "{name} {:?} {} σ={} n={n}: {:.1} MiB, x/y/z {:.1}/{:.1}/{:.1} dB, image {side}²",
                volume.dims,
                kind.name(),
                grid.name(),
                spec.bytes() as f64 / (1 << 20) as f64,
                db[0],
                db[1],
                db[2]
            );
            group.bench_function(BenchmarkId::new("view", &id), |b| {
                b.iter(|| {
                    renderer
                        .render_into(&spec, black_box(&view), side, side, &mut out)
                        .unwrap()
                })
            });
            drop(spec);
            group.bench_function(BenchmarkId::new("prepare", &id), |b| {
                b.iter(|| {
                    OwnedSpectrum::<f16>::prepare_on::<f32>(
                        black_box(&volume),
                        filter,
                        grid.side(volume.dims).unwrap(),
                    )
                    .unwrap()
                })
            });
        }
        group.finish();
    }
}

criterion_group!(grids, benches);
criterion_main!(grids);
