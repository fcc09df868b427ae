//! Criterion benchmarks: the per-view cost of depth cues and shading (paper
//! §3) against the plain projection, on one 128³ f16 spectrum pair (the
//! Gaussian-mixture phantom, kb4, oversampling 1, 128² image). Compare the
//! groups' times as ratios within one run.
//!
//! Run: `cargo bench -p fvr-host --bench cues`.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::shading::{DepthCue, Scene};
use fvr_engine::render::shaded::{gradient_volume, light_ring, SceneRenderer, TypedSpectra};
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use half::f16;

fn scenes(view: &View) -> Vec<(&'static str, Scene)> {
    let lit = |cue: DepthCue| {
        let mut s = Scene {
            cue,
            ambient: [0.2; 3],
            ..Scene::xray()
        };
        for l in light_ring(view, 3, 30.0).unwrap() {
            s.add_light(l).unwrap();
        }
        s
    };
    let cued = |cue: DepthCue| Scene {
        cue,
        ..Scene::xray()
    };
    let linear = DepthCue::Linear {
        front: 1.0,
        back: 0.2,
    };
    let sine = DepthCue::Sine {
        front: 1.0,
        back: 0.2,
    };
    vec![
        ("plain", Scene::xray()),
        ("linear", cued(linear.clone())),
        ("sine", cued(sine.clone())),
        (
            "profile8",
            cued(DepthCue::Profile {
                weights: [0.2, 1.0, 0.2].into_iter().collect(),
                harmonics: 8,
            }),
        ),
        ("shaded3", lit(DepthCue::None)),
        ("shaded3_linear", lit(linear)),
        ("shaded3_sine", lit(sine)),
    ]
}

fn benches(c: &mut Criterion) {
    let n = 128;
    let volume = sample(&GaussianMixture::random(1, n, 8), [n, n, n]);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let density = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
    let gradient =
        OwnedSpectrum::<f16>::prepare::<f32>(&gradient_volume(&volume).unwrap(), filter).unwrap();
    let view = View::along([1.0, 0.3, 0.2]);
    let mut group = c.benchmark_group("view_cues_kb4_f16_128");
    group.sample_size(20);
    for (name, scene) in scenes(&view) {
        let mut renderer = SceneRenderer::<f32>::new(n, filter, &scene).unwrap();
        let mut out = vec![0.0f32; scene.channels() * n * n];
        let g = scene.needs_gradient_spectrum().then_some(&gradient);
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                renderer
                    .render_into(
                        TypedSpectra {
                            density: &density,
                            gradient: g,
                        },
                        &scene,
                        black_box(&view),
                        n,
                        n,
                        &mut out,
                    )
                    .unwrap()
            })
        });
    }
    group.finish();
}

criterion_group!(cues, benches);
criterion_main!(cues);
