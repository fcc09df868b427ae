//! Criterion benchmarks of the accuracy planner (`fvr_engine::plan`),
//! beside the preparation of the spectrum it plans for (its peer: the
//! planner runs before it, on every `fvr render` and `fvr turntable`):
//!
//! - `default`: the `--accuracy 50` walk over every grid, as `fvr
//!   turntable` runs it when nothing is given;
//! - `kb4_x1_f16`: one configuration given explicitly (`--filter kb4
//!   --oversample 1 --precision f16`), predicted only;
//! - `prepare_kb4_x1_f16`: preparing that configuration's spectrum.
//!
//! Volumes: a Gaussian mixture at 128³, and the CT head (256×256×108) when
//! `FVR_CT_HEAD` names `Cranium.inv3` (`bash scripts/fetch-ct-head.sh`).
//!
//! Run: `FVR_CT_HEAD=$(bash scripts/fetch-ct-head.sh) cargo bench -p fvr-host --bench plan`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::filter::FilterKind;
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::plan::{
    choose_among, grid_filter, predict_grid, Candidate, Constraints, ALL_GRIDS,
};
use fvr_engine::spectrum::{AnySpectrum, Precision};
use fvr_host::sources::load_volume;

fn benches(c: &mut Criterion) {
    let mut volumes = vec![("gaussians@128", load_volume("gaussians@128", None).unwrap())];
    if std::env::var_os("FVR_CT_HEAD").is_some() {
        volumes.push(("ct-head", load_volume("ct-head", None).unwrap()));
    }
    let explicit = Candidate {
        filter: FilterKind::Kb4,
        oversample: 1,
        precision: Precision::F16,
    };
    let mut group = c.benchmark_group("plan");
    group.sample_size(10);
    for (name, volume) in &volumes {
        group.bench_function(BenchmarkId::new("default", name), |b| {
            b.iter(|| {
                choose_among(
                    black_box(volume),
                    KbDesign::Auto,
                    50.0,
                    Constraints::default(),
                    &ALL_GRIDS,
                )
                .unwrap()
            })
        });
        group.bench_function(BenchmarkId::new("kb4_x1_f16", name), |b| {
            b.iter(|| {
                predict_grid(
                    black_box(volume),
                    explicit,
                    GridOversampling::X1,
                    KbDesign::Auto,
                )
                .unwrap()
            })
        });
        // The filter as the planner fits it, outside the preparation.
        let filter = grid_filter(
            volume,
            FilterKind::Kb4,
            GridOversampling::X1,
            KbDesign::Auto,
        )
        .unwrap();
        group.bench_function(BenchmarkId::new("prepare_kb4_x1_f16", name), |b| {
            b.iter(|| {
                AnySpectrum::prepare_grid(
                    black_box(volume),
                    filter,
                    Precision::F16,
                    GridOversampling::X1,
                )
                .unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(plan, benches);
criterion_main!(plan);
