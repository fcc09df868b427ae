//! Scratch exploration (not part of the product).
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_host::phantom::{sample, GaussianMixture};
use fvr_host::pipeline::{AnySpectrum, Precision};
use fvr_host::reference::{exact_projection, snr_db};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(64);
    let dims = [n, n, n];
    let ph = GaussianMixture::random(1, n, 8);
    let vol = sample(&ph, dims);
    let design: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(1.0);
    for dir in [[1.0, 0.0, 0.0], [1.0, 0.3, 0.2], [1.0, 1.0, 1.0]] {
        let view = View::along(dir);
        let exact = exact_projection(&ph, dims, &view, n, n).unwrap();
        for (kind, os, prec) in [
            (FilterKind::Linear, 1, Precision::F64),
            (FilterKind::Cubic, 1, Precision::F64),
            (FilterKind::Kb3, 1, Precision::F64),
            (FilterKind::Kb4, 1, Precision::F16),
            (FilterKind::Kb6, 1, Precision::F16),
            (FilterKind::Kb6, 1, Precision::F64),
            (FilterKind::Kb6, 2, Precision::F32),
        ] {
            let f = if design > 0.0 {
                Filter::with_design_oversampling(kind, os, design).unwrap()
            } else {
                let src = fvr_core::spectrum::DenseVolume::new(vol.dims, &vol.data).unwrap();
                let (f, d) = Filter::fit(kind, os, &src).unwrap();
                if dir[1] == 0.0 {
                    println!(
                        "  fit {} os{os}: design {d:.2} beta {:.2}",
                        kind.name(),
                        f.beta()
                    );
                }
                f
            };
            let t = std::time::Instant::now();
            let spec = AnySpectrum::prepare(&vol, f, prec).unwrap();
            let img = spec.render(f, &view, n, n).unwrap();
            println!(
                "{dir:?} {} os{os} {prec}: {:.2} dB ({:?})",
                kind.name(),
                snr_db(&exact, &img),
                t.elapsed()
            );
        }
    }
}
