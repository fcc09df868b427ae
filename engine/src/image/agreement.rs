//! Agreement of two images in dB, the measure every accuracy figure uses.

/// Agreement of `test` with `reference` in dB:
/// `10·log10(Σ ref² / Σ (test − ref)²)`. Identical images give `+∞`.
///
/// # Panics
/// If the lengths differ.
pub fn snr_db<T: Copy + Into<f64>>(reference: &[T], test: &[T]) -> f64 {
    assert_eq!(reference.len(), test.len(), "images must have equal sizes");
    let (signal, noise) = reference
        .iter()
        .zip(test)
        .fold((0.0f64, 0.0f64), |(s, n), (&r, &t)| {
            let (r, t): (f64, f64) = (r.into(), t.into());
            (s + r * r, n + (t - r) * (t - r))
        });
    10.0 * (signal / noise).log10()
}

/// Largest absolute pixel difference.
pub fn max_abs_error<T: Copy + Into<f64>>(reference: &[T], test: &[T]) -> f64 {
    reference
        .iter()
        .zip(test)
        .map(|(&r, &t)| (t.into() - r.into()).abs())
        .fold(0.0, f64::max)
}
