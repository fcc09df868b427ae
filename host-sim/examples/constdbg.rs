//! Scratch: debug constant volume.
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_host::pipeline::{AnySpectrum, Precision};
use fvr_host::reference::snr_db;
use fvr_host::volume::Volume;
fn main() {
    let n = 32;
    for val in [1.0f32, 2.0, 3.0] {
        let mut volume = Volume::zeros([n, n, n]);
        volume.data.fill(1.0);
        if val == 2.0 {
            volume = fvr_host::phantom::sample(
                &fvr_host::phantom::GaussianMixture::random(1, n, 8),
                [n, n, n],
            );
        }
        if val == 3.0 {
            volume = fvr_host::phantom::sample(
                &fvr_host::phantom::SheppLogan::new([n, n, n]),
                [n, n, n],
            );
        }
        let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
        let view = View::along([1.0, 0.0, 0.0]);
        let mut imgs = vec![];
        for p in Precision::ALL {
            let s = AnySpectrum::prepare(&volume, filter, p).unwrap();
            let img = s.render(&view, n, n).unwrap();
            let vs: f64 = volume.data.iter().map(|&v| v as f64).sum();
            println!("   estimate {:.1} dB", s.storage_snr_estimate_db(vs));
            println!(
                "{val} {p}: sum {:.6e} px(16,16) {:.4e} px(0,0) {:.4e}",
                img.iter().sum::<f64>(),
                img[16 * n + 16],
                img[0]
            );
            imgs.push(img);
        }
        println!(
            "  f16 vs f64 {:.2} dB, f32 vs f64 {:.2}",
            snr_db(&imgs[2], &imgs[0]),
            snr_db(&imgs[2], &imgs[1])
        );
    }
}
