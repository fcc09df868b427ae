//! Numerical stability at the extremes, for every storage format. Each test
//! name states the behaviour it checks; docs/precision.md tabulates the
//! measured numbers (`fvr precision --extremes`).
//!
//! Floors against the f64 pipeline are tied to the arithmetic: a format of
//! unit roundoff `u` rounding `r` times adds relative noise of variance
//! `r·u²/3` to each coefficient, so its images sit about
//! `−20·log10(u) − 10·log10(4r/3)` dB from f64, less the premultiplication
//! gain, which automatic oversampling keeps under
//! `CONDITIONING_LIMIT_DB` (20 dB). Every image of every test is checked
//! to be free of NaN and infinity.

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::num::Sample;
use fvr_core::num::{Arithmetic, BlockLayout, Blocking, Format, FormatName};
use fvr_core::spectrum::{premultiplier_table, scale_for_target};
use fvr_engine::plan::filter::{
    choose_filter, choose_oversampling, premultiplication_gain_db, KbDesign, CONDITIONING_LIMIT_DB,
};
use fvr_engine::volume::Volume;
use fvr_host::reference::snr_db;
use fvr_host::studies::precision::{measure_extremes, ExtremeRow, Subject};

const N: usize = 32;
const LINE: Blocking = Blocking::Blocks(BlockLayout::Line);

/// The formats every case runs: the 16-bit floats, Q15 per line, the 8-bit
/// e4m3 and Q7 per line, and f32.
fn formats() -> Vec<Format> {
    vec![
        Format::F16,
        Format::Bf16,
        Format::Minifloat16(4),
        Format::Q15(LINE),
        Format::Minifloat8(4),
        Format::Q7(LINE),
        Format::F32,
    ]
}

/// The floor (dB against f64) a format must reach once the problem is
/// conditioned (module docs); `None` where the format's error is not
/// relative (8-bit formats reach 30–60 dB, measured in the docs only) or
/// where the format cannot hold the input in place (e4m11 per pass:
/// its 4-bit exponent spans 2^±7, and the scaling rule puts voxels `n³`
/// below the top).
fn floor_db(format: Format, arithmetic: Arithmetic, n: usize) -> Option<f64> {
    let u = match format {
        Format::Q15(Blocking::Blocks(_)) => 2f64.powi(-16),
        Format::Minifloat16(4) if arithmetic != Arithmetic::HostOnce => return None,
        f if f.bytes_per_voxel(n) < 2.0 => return None,
        f => f.unit_roundoff()?,
    };
    let roundings = match arithmetic {
        Arithmetic::PerPass => 4.0,
        Arithmetic::PerStage => 4.0 + 3.0 * (n as f64).log2(),
        Arithmetic::HostOnce => 1.0,
    };
    Some(-20.0 * u.log10() - 10.0 * (4.0 * roundings / 3.0).log10() - CONDITIONING_LIMIT_DB)
}

/// The stability cases at N³ with automatic oversampling, measured once for
/// all tests.
fn auto_rows() -> &'static [ExtremeRow] {
    static ROWS: std::sync::OnceLock<Vec<ExtremeRow>> = std::sync::OnceLock::new();
    ROWS.get_or_init(|| measure_extremes(N, &formats(), None).unwrap())
}

fn rows_of<'a>(rows: &'a [ExtremeRow], case: &str) -> Vec<&'a ExtremeRow> {
    let got: Vec<&ExtremeRow> = rows.iter().filter(|r| r.case == case).collect();
    assert!(!got.is_empty(), "no rows for {case}");
    got
}

/// Every row is finite, measured, and at its floor.
fn assert_floors(rows: &[&ExtremeRow]) {
    for r in rows {
        let name = format!(
            "{} {} {}",
            r.case,
            FormatName(r.format),
            r.arithmetic.name()
        );
        assert_eq!(r.non_finite, 0, "{name}: NaN or Inf in the image");
        let snr = *r.snr_f64.as_ref().unwrap_or_else(|e| panic!("{name}: {e}"));
        if let Some(floor) = floor_db(r.format, r.arithmetic, N) {
            assert!(snr >= floor, "{name}: {snr:.1} dB < floor {floor:.1} dB");
        }
    }
}

#[test]
fn constant_volume_at_oversampling_1_breaks_16_bit_formats_and_auto_oversampling_2_restores_their_rounding_floor(
) {
    // Oversampling 1: kb4 premultiplication multiplies the faces by ~200 per
    // axis, the corners by ~10⁷; the storage noise gain is ~96 dB.
    let fixed = measure_extremes(N, &formats(), Some(1)).unwrap();
    for r in rows_of(&fixed, "constant 1") {
        assert!(r.gain_db > 90.0, "gain {:.1} dB", r.gain_db);
        assert_eq!(r.non_finite, 0);
        let snr = *r.snr_f64.as_ref().unwrap();
        match (r.format, r.arithmetic) {
            // f32's 2^-24 absorbs it (the foundation measured 66 dB)...
            (Format::F32, _) => assert!(snr > 60.0, "f32 {snr:.1}"),
            // ...no 16-bit or 8-bit format does.
            _ => assert!(snr < 25.0, "{}: {snr:.1} dB", FormatName(r.format)),
        }
    }
    // Automatic oversampling picks 2, where every 16-bit format is back at
    // its rounding floor.
    let rows = rows_of(auto_rows(), "constant 1");
    assert!(rows.iter().all(|r| r.oversample == 2));
    assert_floors(&rows);
}

/// Along an axis at oversampling 2 the band-limited interpolant of a constant
/// volume integrates to exactly `c·n` on every pixel (a trigonometric
/// polynomial integrated over whole periods is the sum of its samples). The
/// pipeline reaches it up to kb4's aliasing at the data's edge, ν = ¼
/// (three axes, RMS factor √A(¼)), and f16 up to that plus its rounding.
#[test]
fn constant_volume_projects_to_c_times_n_along_an_axis_up_to_kb4_aliasing_in_f64_and_f16() {
    let c = 1000.0f32;
    let volume = Volume {
        dims: [N; 3],
        data: vec![c; N * N * N],
        spacing: fvr_engine::volume::DEFAULT_SPACING,
        orientation: None,
    };
    assert_eq!(
        choose_oversampling(&volume, FilterKind::Kb4, KbDesign::Auto),
        Ok(2)
    );
    let filter = choose_filter(&volume, FilterKind::Kb4, 2, KbDesign::Auto).unwrap();
    let bound = 3.0 * filter.aliasing_power(0.25).sqrt();
    assert!(bound < 2e-3, "kb4 at σ = 2 aliases {bound:e} at ν = ¼");
    let view = View::along([1.0, 0.0, 0.0]);
    // Pixels whose ray runs through the samples get c·n; the first row and
    // column sit one voxel outside the box (p = c + (col − W/2)·r + …) and
    // integrate the zero padding.
    let frame = view.frame().unwrap();
    let centre = fvr_core::geometry::center([N; 3]);
    let mut exact = Vec::with_capacity(N * N);
    for row in 0..N {
        for col in 0..N {
            let p = frame.pixel_position(centre, N, N, col as f64, row as f64);
            let inside = p[1..]
                .iter()
                .all(|&x| (-0.01..N as f64 - 0.99).contains(&x));
            exact.push(if inside { c as f64 * N as f64 } else { 0.0 });
        }
    }
    let mut subject = Subject::new("constant", volume, None, filter, vec![view]);
    for format in [Format::F64, Format::F16] {
        let (images, _) = subject.render_format(format, Arithmetic::PerPass).unwrap();
        let peak = c as f64 * N as f64;
        let worst = images[0]
            .iter()
            .zip(&exact)
            .map(|(v, e)| (v - e).abs() / peak)
            .fold(0.0, f64::max);
        // The aliasing factor is an RMS over 16 sample offsets; the worst
        // offset is at most √16 times it.
        let tolerance = 4.0 * bound + if format == Format::F16 { 1e-3 } else { 0.0 };
        assert!(
            worst <= tolerance,
            "{}: relative error {worst:.2e} > {tolerance:.2e}",
            FormatName(format)
        );
        assert!(snr_db(&exact, &images[0]) > 40.0);
    }
}

/// A centred impulse premultiplies to one value at the transform origin; its
/// DHT is that value at every frequency, and every butterfly only adds zeros
/// or multiplies them, so the stored spectrum is flat *exactly* in every
/// format and every arithmetic.
#[test]
fn impulse_spectrum_is_exactly_flat_in_every_format_and_images_reach_their_floor() {
    use fvr_core::dht::Rounding;
    use fvr_core::num::{bf16, Minifloat16, Minifloat8};
    use fvr_host::studies::precision::StoredSpectrum;
    use half::f16;
    let mut volume = Volume::zeros([16; 3]);
    let centre = volume.index(8, 8, 8);
    volume.data[centre] = 3.0;
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    fn flat<S: Sample>(volume: &Volume, filter: Filter, rounding: Rounding) {
        let s = StoredSpectrum::<S>::prepare::<f32>(volume, filter, rounding).unwrap();
        let spec = s.view();
        let first = spec.data()[0];
        assert!(first.is_finite() && first.to_f64() > 0.0, "{}", S::NAME);
        assert!(
            spec.data().iter().all(|v| *v == first),
            "{} {rounding:?}: not flat",
            S::NAME
        );
    }
    for rounding in [Rounding::PerPass, Rounding::PerStage] {
        flat::<f16>(&volume, filter, rounding);
        flat::<bf16>(&volume, filter, rounding);
        flat::<Minifloat16<4>>(&volume, filter, rounding);
        flat::<Minifloat8<4>>(&volume, filter, rounding);
        flat::<f32>(&volume, filter, rounding);
    }
    assert_floors(&rows_of(auto_rows(), "impulse"));
}

/// The checkerboard (−1)^(i+j+k) lives at the Nyquist corner; a projection
/// over an even number of voxels cancels it, so every image is near zero.
/// It fills its box, so auto oversampling picks 2. The f64 image stays below
/// 10⁻³ of `n·max|v|` (the kernel's aliasing at ν = ¼ leaks the corner into
/// the slice); f32 and the 16-bit formats add their rounding of a spectrum
/// whose energy is all at the corner, at most 2⁻⁶·n (measured 10⁻⁴–10⁻³·n
/// for 16 bits); 8-bit formats stay finite.
#[test]
fn nyquist_checkerboard_projects_to_near_zero_in_every_16_bit_format_and_8_bit_stays_finite() {
    for r in rows_of(auto_rows(), "nyquist checkerboard") {
        assert_eq!(r.oversample, 2);
        assert_eq!(r.non_finite, 0, "{}", FormatName(r.format));
        let relative = r.max_error / r.line_scale;
        if r.format.bytes_per_voxel(N) >= 2.0 {
            assert!(
                relative < 2f64.powi(-6),
                "{} {}: {relative:.2e}",
                FormatName(r.format),
                r.arithmetic.name()
            );
        }
    }
}

/// A full-range u16 volume of 65535s at 512³ has DC 65535·512³ ≈ 8.8e12
/// (more after premultiplication). Checked without allocating: the bound
/// Σ|g| of a constant volume is `c·(Σ_x p(x))³` from the premultiplier
/// table, and the scaling rule must bring it under every format's range at
/// both oversamplings, with a scale f32 arithmetic holds exactly.
#[test]
fn full_range_u16_volume_at_512_cubed_cannot_overflow_any_format_by_the_scaling_rule() {
    use fvr_core::num::{bf16, Minifloat16, Minifloat8, Q15, Q7};
    use half::f16;
    let c = 65535.0f64;
    let side = 512usize;
    assert!((c * (side as f64).powi(3) - 8.796e12).abs() < 1e9);
    fn fits<S: Sample>(bound: f64) {
        let s = scale_for_target(bound, S::SCALE_LOG2);
        let top = s * bound;
        let t = 2f64.powi(S::SCALE_LOG2);
        assert!(top <= t && top > t / 2.0, "{}: s·bound {top:e}", S::NAME);
        // Every value met during the transform is at most 2·s·Σ|g|.
        assert!(2.0 * top <= S::MAX_FINITE, "{}", S::NAME);
        assert!(S::from_f64(2.0 * top).is_finite(), "{}", S::NAME);
        assert_eq!((s as f32) as f64, s, "{}: scale not exact in f32", S::NAME);
    }
    for oversample in [1u32, 2] {
        let filter = Filter::new(FilterKind::Kb4, oversample).unwrap();
        let n = side * oversample as usize;
        let mut p = vec![0.0f64; n];
        premultiplier_table(&filter, n, &mut p);
        let axis: f64 = (0..side).map(|i| p[(i + n - side / 2) % n]).sum();
        // Σ|g| of a positive volume is its premultiplied DC.
        let bound = c * axis.powi(3);
        assert!(bound > 1e12 && bound.is_finite(), "{bound:e}");
        fits::<f16>(bound);
        fits::<bf16>(bound);
        fits::<Minifloat16<2>>(bound);
        fits::<Minifloat16<3>>(bound);
        fits::<Minifloat16<4>>(bound);
        fits::<Minifloat16<6>>(bound);
        fits::<Minifloat16<7>>(bound);
        fits::<Minifloat8<2>>(bound);
        fits::<Minifloat8<3>>(bound);
        fits::<Minifloat8<4>>(bound);
        fits::<Minifloat8<5>>(bound);
        fits::<Q15>(bound);
        fits::<Q7>(bound);
        fits::<f32>(bound);
    }
    // The same volume at 32³ through the real pipeline: no overflow anywhere,
    // and the 16-bit formats at their floors.
    assert_floors(&rows_of(auto_rows(), "u16 65535"));
}

/// Scaling the Gaussian phantom changes nothing that matters: by an exact
/// power of two (2^-20) the images are the unscaled ones times 2^-20, bit
/// for bit, in every format (the power-of-two scale absorbs it exactly); by
/// 1e-6 (voxels near 1e-6, where f16's subnormals start at 6e-5) and by
/// 1e-30 every format stays at its floor and within 10 dB of the unscaled
/// volume. (They are different rounding realizations: the noise of a few
/// low-frequency coefficients dominates, and its energy varies by several dB
/// from one scaling to another.)
#[test]
fn volume_scaled_by_2_pow_minus_20_is_bit_identical_and_by_1e_minus_6_or_1e_minus_30_keeps_its_floor(
) {
    use fvr_engine::volume::phantom::{sample, GaussianMixture};
    let base = sample(&GaussianMixture::random(1, N, 8), [N; 3]);
    let filter = choose_filter(&base, FilterKind::Kb4, 1, KbDesign::Auto).unwrap();
    let views: Vec<View> = fvr_host::studies::precision::VIEWS
        .iter()
        .map(|&d| View::along(d))
        .collect();
    let mut a = Subject::new("base", base.clone(), None, filter, views.clone());
    let (ra, _) = a.render_format(Format::F64, Arithmetic::PerPass).unwrap();
    let cases = [
        Format::F16,
        Format::Bf16,
        Format::Minifloat16(4),
        Format::Q15(LINE),
        Format::F32,
    ];
    for factor in [2f32.powi(-20), 1e-6, 1e-30] {
        let scaled = Volume {
            dims: base.dims,
            data: base.data.iter().map(|v| v * factor).collect(),
            spacing: fvr_engine::volume::DEFAULT_SPACING,
            orientation: None,
        };
        let mut b = Subject::new("scaled", scaled, None, filter, views.clone());
        let (rb, _) = b.render_format(Format::F64, Arithmetic::PerPass).unwrap();
        for format in cases {
            for arithmetic in [Arithmetic::PerPass, Arithmetic::HostOnce] {
                if format.check(arithmetic, N).is_err() {
                    continue;
                }
                let (ia, _) = a.render_format(format, arithmetic).unwrap();
                let (ib, _) = b.render_format(format, arithmetic).unwrap();
                assert!(ib.iter().flatten().all(|v| v.is_finite()));
                let name = format!("{} {} x{factor:e}", FormatName(format), arithmetic.name());
                if factor == 2f32.powi(-20) {
                    for (x, y) in ia.iter().flatten().zip(ib.iter().flatten()) {
                        assert_eq!(x * 2f64.powi(-20), *y, "{name}");
                    }
                    continue;
                }
                let sa = snr_db(&ra.concat(), &ia.concat());
                let sb = snr_db(&rb.concat(), &ib.concat());
                assert!(
                    (sa - sb).abs() <= 10.0,
                    "{name}: {sa:.1} dB unscaled, {sb:.1} dB"
                );
                if let Some(floor) = floor_db(format, arithmetic, N) {
                    assert!(sb >= floor, "{name}: {sb:.1} dB < {floor:.1}");
                }
            }
        }
    }
    assert_floors(&rows_of(auto_rows(), "gaussians x 1e-6"));
}

/// CT in Hounsfield units is negative almost everywhere (air −1000) and
/// fills its box: at oversampling 1 the gain is ~96 dB and f16 is lost; auto
/// oversampling picks 2 and every 16-bit format reaches its floor. A
/// mixed-sign Gaussian volume (half the components negative) is
/// well-conditioned at oversampling 1.
#[test]
fn hounsfield_units_fill_the_box_and_need_oversampling_2_mixed_sign_gaussians_do_not() {
    let hu = rows_of(auto_rows(), "shepp-logan in HU");
    assert!(hu
        .iter()
        .all(|r| r.gain_db > CONDITIONING_LIMIT_DB && r.oversample == 2));
    assert_floors(&hu);

    use fvr_engine::volume::phantom::{sample, GaussianMixture};
    let mut mix = GaussianMixture::random(3, N, 8);
    for (i, g) in mix.components.iter_mut().enumerate() {
        if i % 2 == 1 {
            g.amplitude = -g.amplitude;
        }
    }
    let volume = sample(&mix, [N; 3]);
    assert!(volume.data.iter().any(|&v| v < -1e-3) && volume.data.iter().any(|&v| v > 1e-3));
    assert_eq!(
        choose_oversampling(&volume, FilterKind::Kb4, KbDesign::Auto),
        Ok(1)
    );
    let filter = choose_filter(&volume, FilterKind::Kb4, 1, KbDesign::Auto).unwrap();
    assert!(premultiplication_gain_db(&volume, filter).unwrap() < 6.0);
    let views = fvr_host::studies::precision::VIEWS
        .iter()
        .map(|&d| View::along(d))
        .collect();
    let mut subject = Subject::new("mixed", volume, Some(Box::new(mix)), filter, views);
    let (reference, _) = subject
        .render_format(Format::F64, Arithmetic::PerPass)
        .unwrap();
    for format in [Format::F16, Format::Bf16, Format::Q15(LINE)] {
        let arithmetic = if format == Format::Q15(LINE) {
            Arithmetic::HostOnce
        } else {
            Arithmetic::PerPass
        };
        let (images, _) = subject.render_format(format, arithmetic).unwrap();
        let floor = floor_db(format, arithmetic, N).unwrap();
        for (i, r) in images.iter().zip(&reference) {
            assert!(i.iter().all(|v| v.is_finite()));
            let snr = snr_db(r, i);
            assert!(
                snr >= floor,
                "{}: {snr:.1} < {floor:.1}",
                FormatName(format)
            );
        }
    }
}

/// Views exactly along an axis and a diagonal, and 1e-7 rad off them: the
/// slice moves by at most 1e-7·√3·n/2 ≈ 2.8e-6 index units; kb4's slope is
/// below 1.5 per unit on each of 3 axes, so every tap weight moves by less
/// than 1.3e-5 of itself (98 dB). The spectrum is the same for both views, so
/// in every format the two images must agree to ≥ 90 dB (the margin is
/// the f32 rounding of the weights).
#[test]
fn views_1e_minus_7_rad_off_an_axis_or_diagonal_are_continuous_in_every_format() {
    use fvr_engine::volume::phantom::{sample, GaussianMixture};
    let phantom = GaussianMixture::random(1, N, 8);
    let volume = sample(&phantom, [N; 3]);
    let filter = choose_filter(&volume, FilterKind::Kb4, 1, KbDesign::Auto).unwrap();
    let eps = 1e-7f64;
    let pairs = [
        ([1.0, 0.0, 0.0], [1.0, eps.tan(), 0.0]),
        ([0.0, 0.0, 1.0], [eps.tan(), 0.0, 1.0]),
        ([1.0, 1.0, 1.0], [1.0 + eps, 1.0 - eps, 1.0]),
    ];
    for (exact, off) in pairs {
        let up = if exact[2] == 1.0 && exact[0] == 0.0 {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        };
        let views = vec![View { dir: exact, up }, View { dir: off, up }];
        let mut s = Subject::new("continuity", volume.clone(), None, filter, views);
        for format in formats() {
            for arithmetic in fvr_host::studies::precision::modes_for(format) {
                let (images, _) = s.render_format(format, arithmetic).unwrap();
                assert!(images.iter().flatten().all(|v| v.is_finite()));
                let snr = snr_db(&images[0], &images[1]);
                assert!(
                    snr >= 90.0,
                    "{} {} {exact:?}: {snr:.1} dB between the view and 1e-7 rad off",
                    FormatName(format),
                    arithmetic.name()
                );
            }
        }
    }
}

/// Volumes of side 1, 2 and 4 run through every format and arithmetic at
/// both oversamplings without error or NaN (bricks larger than the grid are
/// refused by name), and f16 reaches its floor against f64 at the
/// oversampling auto chooses: these tiny volumes fill their grid, so at
/// oversampling 1 even f32 loses to the premultiplication (n = 2: 20% off
/// f64), and auto picks 2.
#[test]
fn sizes_1_2_and_4_work_in_every_format() {
    use fvr_engine::volume::phantom::SplitMix64;
    let mut rng = SplitMix64::new(11);
    for n in [1usize, 2, 4] {
        let volume = Volume {
            dims: [n; 3],
            data: (0..n * n * n)
                .map(|_| rng.next_f64() as f32 + 0.5)
                .collect(),
            spacing: fvr_engine::volume::DEFAULT_SPACING,
            orientation: None,
        };
        for o in [1u32, 2] {
            let filter = choose_filter(&volume, FilterKind::Kb4, o, KbDesign::Auto).unwrap();
            let views = fvr_host::studies::precision::VIEWS
                .iter()
                .map(|&d| View::along(d))
                .collect();
            let mut s = Subject::new("small", volume.clone(), None, filter, views);
            let (reference, _) = s.render_format(Format::F64, Arithmetic::PerPass).unwrap();
            assert!(reference.iter().flatten().all(|v| v.is_finite()));
            let grid = fvr_core::volume::padded_size([n; 3], o).unwrap();
            for format in fvr_host::studies::precision::default_formats() {
                for arithmetic in fvr_host::studies::precision::modes_for(format) {
                    if let Format::Q15(Blocking::Blocks(BlockLayout::Brick(b)))
                    | Format::Q7(Blocking::Blocks(BlockLayout::Brick(b))) = format
                    {
                        if BlockLayout::Brick(b).exponent_count(grid).is_err() {
                            // A brick larger than the grid is a configuration error.
                            let err = s.render_format(format, arithmetic).unwrap_err();
                            assert!(err.contains("does not divide"), "{err}");
                            continue;
                        }
                    }
                    let got = s.render_format(format, arithmetic);
                    let (images, _) =
                        got.unwrap_or_else(|e| panic!("n={n} σ={o} {}: {e}", FormatName(format)));
                    assert!(images.iter().flatten().all(|v| v.is_finite()));
                    let auto = choose_oversampling(&volume, FilterKind::Kb4, KbDesign::Auto);
                    if format == Format::F16 && arithmetic == Arithmetic::PerPass && auto == Ok(o) {
                        for (i, r) in images.iter().zip(&reference) {
                            if r.iter().all(|v| *v == 0.0) {
                                // The pixel sits off the one voxel: both are 0.
                                assert!(i.iter().all(|v| v.abs() < 1e-3));
                                continue;
                            }
                            let floor = floor_db(format, arithmetic, n.max(2)).unwrap();
                            assert!(snr_db(r, i) >= floor, "n={n}: {:.1}", snr_db(r, i));
                        }
                    }
                }
            }
        }
    }
}
