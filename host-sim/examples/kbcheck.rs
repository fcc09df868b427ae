//! Scratch: scan KB beta at sigma=1: worst aliasing over |nu|<=numax and offsets d.
use fvr_core::filter::bessel_i0;
fn main() {
    let pi = std::f64::consts::PI;
    for w in [3usize, 4, 5, 6] {
        for numax in [0.25, 0.4] {
            let mut best = (0.0, 0.0);
            let mut beatty = 0.0;
            for bi in 0..200 {
                let beta = 1.0 + bi as f64 * 0.1;
                let kern = |t: f64| {
                    let r = 2.0 * t.abs() / w as f64;
                    if r > 1.0 {
                        0.0
                    } else {
                        bessel_i0(beta * (1.0 - r * r).sqrt()) / bessel_i0(beta)
                    }
                };
                let resp = |nu: f64| {
                    let z2 = beta * beta - (pi * w as f64 * nu).powi(2);
                    let z = z2.abs().sqrt();
                    let r = if z2 > 1e-12 {
                        z.sinh() / z
                    } else if z2 < -1e-12 {
                        z.sin() / z
                    } else {
                        1.0
                    };
                    w as f64 * r / bessel_i0(beta)
                };
                let mut worst: f64 = 0.0;
                let mut mean = 0.0;
                let mut cnt = 0.0;
                for ni in 0..=8 {
                    let nu = numax * ni as f64 / 8.0;
                    for di in 0..20 {
                        let d = di as f64 / 20.0;
                        let j0 = (d - w as f64 / 2.0).floor() as i64 + 1;
                        let (mut re, mut im) = (0.0, 0.0);
                        for m in 0..w as i64 {
                            let j = j0 + m;
                            let k = kern(d - j as f64);
                            let ph = -2.0 * pi * (j as f64 - d) * nu;
                            re += k * ph.cos();
                            im += k * ph.sin();
                        }
                        let h = resp(nu);
                        let e2 = ((re - h).powi(2) + im * im) / (h * h);
                        worst = worst.max(e2);
                        mean += e2;
                        cnt += 1.0;
                    }
                }
                let db = 10.0 * (mean / cnt).log10();
                if db < best.1 {
                    best = (beta, db);
                }
                let bb = pi * ((w * w) as f64 * 0.25 - 0.8).sqrt();
                if (beta - bb).abs() < 0.05 {
                    beatty = db;
                }
                let _ = worst;
            }
            println!(
                "W={w} numax={numax}: best beta {:.1} mean {:.1} dB; beatty mean {:.1} dB",
                best.0, best.1, beatty
            );
        }
    }
}
