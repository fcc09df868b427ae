//! The radiograph ("film") display of an X-ray projection.
//!
//! A projection holds line integrals `p = ∫μ dt` (mm × volume units), shown
//! by default on a linear scale. A radiograph shows the attenuation of the
//! beam instead: the film darkens with the photons that reach it, `exp(−k·p)`,
//! and is viewed as a negative, so attenuating matter is bright:
//! `1 − exp(−k·p)`. Dense structures (bone) saturate towards white, soft
//! tissue keeps its contrast, and the glow of long paths through a head is
//! compressed. The map is monotonic, so it orders pixels as the line
//! integrals do; it is a display only (NRRD outputs keep the integrals),
//! and changes no accuracy figure, which is measured on the integrals.

/// How an X-ray image is shown.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Display {
    /// The line integrals, windowed linearly.
    #[default]
    Linear,
    /// `1 − exp(−k·p)`; `k` from the image ([`film_gain`]) when `None`.
    Film(Option<f64>),
}

impl std::str::FromStr for Display {
    type Err = String;

    /// `linear`, `film` or `film:K` (K > 0, per mm × volume unit).
    fn from_str(s: &str) -> Result<Self, String> {
        match s.split_once(':') {
            None if s == "linear" => Ok(Display::Linear),
            None if s == "film" => Ok(Display::Film(None)),
            Some(("film", k)) => match k.trim().parse::<f64>() {
                Ok(k) if k.is_finite() && k > 0.0 => Ok(Display::Film(Some(k))),
                _ => Err(format!(
                    "film:K needs a finite K > 0 (attenuation per mm x volume unit), got `{k}`"
                )),
            },
            _ => Err(format!(
                "expected linear, film or film:K, got `{}`",
                crate::text::bounded(s)
            )),
        }
    }
}

/// The attenuation `k` that shows the 99th percentile of the positive line
/// integrals at 95% attenuation (`1 − e⁻³`): the body's long paths near
/// white, the thin ones still graded. `None` when no pixel is positive.
pub fn film_gain(data: &[f64]) -> Option<f64> {
    let mut positive: Vec<f64> = data.iter().copied().filter(|&v| v > 0.0).collect();
    if positive.is_empty() {
        return None;
    }
    let at = ((positive.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p99, _) = positive.select_nth_unstable_by(at, f64::total_cmp);
    let k = 3.0 / *p99;
    k.is_finite().then_some(k)
}

/// Map `data` in place to `1 − exp(−k·max(p, 0))`, in `[0, 1)`. Negative
/// integrals (ringing around edges) show as no attenuation.
pub fn apply_film(data: &mut [f64], k: f64) {
    for v in data {
        *v = -(-k * v.max(0.0)).exp_m1();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_refuses() {
        assert_eq!("linear".parse(), Ok(Display::Linear));
        assert_eq!("film".parse(), Ok(Display::Film(None)));
        assert_eq!("film:0.02".parse(), Ok(Display::Film(Some(0.02))));
        for bad in [
            "film:0", "film:-1", "film:inf", "film:x", "fil", "linear:2", "",
        ] {
            assert!(bad.parse::<Display>().is_err(), "{bad}");
        }
    }

    #[test]
    fn the_gain_puts_the_99th_percentile_at_95_percent() {
        let data: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.5 - 100.0).collect();
        let k = film_gain(&data).unwrap();
        // Positive values 0.5 … 400; their 99th percentile is about 396.
        let p99 = 3.0 / k;
        assert!((p99 - 396.0).abs() <= 0.5, "{p99}");
        let mut mapped = data.clone();
        apply_film(&mut mapped, k);
        // Monotonic, in [0, 1), zero for no attenuation.
        assert!(mapped.windows(2).all(|w| w[0] <= w[1]));
        assert!(mapped.iter().all(|&v| (0.0..1.0).contains(&v)));
        assert_eq!(mapped[0], 0.0);
        let at = data.iter().position(|&v| v >= p99).unwrap();
        assert!((mapped[at] - (1.0 - (-3.0f64).exp())).abs() < 0.01);
        assert_eq!(film_gain(&[0.0, -1.0]), None);
    }
}
