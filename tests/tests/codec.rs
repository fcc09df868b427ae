//! The f16 storage codec over all 65,536 bit patterns.

use fvr_core::num::{Real, Sample};
use half::f16;

#[test]
fn every_f16_bit_pattern_round_trips_through_f32_and_f64() {
    for bits in 0..=u16::MAX {
        let h = f16::from_bits(bits);
        let wide32: f32 = Real::load(h);
        let wide64: f64 = Real::load(h);
        if h.is_nan() {
            assert!(wide32.is_nan() && wide64.is_nan(), "{bits:#06x}");
            assert!(!Sample::is_finite(h));
            continue;
        }
        assert_eq!(wide32 as f64, wide64, "{bits:#06x}: widening is exact");
        let back32: f16 = wide32.store();
        let back64: f16 = wide64.store();
        assert_eq!(back32.to_bits(), bits, "{bits:#06x} via f32");
        assert_eq!(back64.to_bits(), bits, "{bits:#06x} via f64");
        assert_eq!(Sample::is_finite(h), wide64.is_finite(), "{bits:#06x}");
    }
}

#[test]
fn f32_to_f16_rounds_to_nearest_even_between_every_pair_of_neighbours() {
    // Between consecutive positive finite f16 values a < b, the midpoint must
    // round to whichever has an even significand, and points just inside the
    // interval to the nearer one.
    for bits in 0..0x7BFFu16 {
        let (a, b) = (f16::from_bits(bits), f16::from_bits(bits + 1));
        let (fa, fb) = (a.to_f64(), b.to_f64());
        let mid = 0.5 * (fa + fb);
        let expect_mid = if bits % 2 == 0 { bits } else { bits + 1 };
        let got: f16 = Real::store(mid);
        assert_eq!(got.to_bits(), expect_mid, "midpoint above {bits:#06x}");
        let got32: f16 = Real::store(mid as f32);
        assert_eq!(
            got32.to_bits(),
            expect_mid,
            "f32 midpoint above {bits:#06x}"
        );
        let below: f16 = Real::store(mid - (fb - fa) * 0.25);
        assert_eq!(below.to_bits(), bits);
        let above: f16 = Real::store(mid + (fb - fa) * 0.25);
        assert_eq!(above.to_bits(), bits + 1);
    }
}

#[test]
fn values_beyond_the_f16_range_become_infinite_and_are_reported_non_finite() {
    // 65520 is the midpoint between 65504 (max) and the next step: rounds up to ∞.
    let over: f16 = Real::store(65520.0f32);
    assert!(!Sample::is_finite(over));
    let max: f16 = Real::store(65519.0f32);
    assert_eq!(max.to_f64(), 65504.0);
    assert_eq!(<f16 as Sample>::MAX_FINITE, 65504.0);
}

#[test]
fn fast_f16_widening_is_bit_identical_to_half_for_every_pattern() {
    for bits in 0..=u16::MAX {
        let fast = fvr_core::num::f16_bits_to_f32(bits);
        let reference = f16::from_bits(bits).to_f32();
        assert_eq!(fast.to_bits(), reference.to_bits(), "{bits:#06x}");
        // And the storage trait uses it.
        assert_eq!(
            Sample::to_f32(f16::from_bits(bits)).to_bits(),
            reference.to_bits()
        );
    }
    // The subnormal and boundary cases the rebias relies on, by value.
    assert_eq!(fvr_core::num::f16_bits_to_f32(0x0001), 2f32.powi(-24));
    assert_eq!(
        fvr_core::num::f16_bits_to_f32(0x03FF),
        1023.0 * 2f32.powi(-24)
    );
    assert_eq!(fvr_core::num::f16_bits_to_f32(0x0400), 2f32.powi(-14));
    assert_eq!(fvr_core::num::f16_bits_to_f32(0x7BFF), 65504.0);
    assert_eq!(
        fvr_core::num::f16_bits_to_f32(0x8000).to_bits(),
        (-0.0f32).to_bits()
    );
    assert_eq!(fvr_core::num::f16_bits_to_f32(0xFC00), f32::NEG_INFINITY);
}

#[test]
fn raw_f16_widening_times_two_pow_112_is_the_value_for_every_finite_pattern() {
    // The device's hot loops fold 2^112 into a weight; (w·2^112)·raw must
    // equal w·value bit for bit, which holds when raw·2^112 is the value
    // exactly.
    let two_pow_112 = f32::exp2i(112);
    for bits in (0..0x7C00u16).chain(0x8000..0xFC00u16) {
        let raw = fvr_core::num::f16_bits_to_f32_raw(bits);
        let value = f16::from_bits(bits).to_f32();
        assert_eq!(
            (raw * two_pow_112).to_bits(),
            value.to_bits(),
            "{bits:#06x}"
        );
        for w in [0.3f32, -1.7e-3, 0.999_999_9] {
            assert_eq!(
                ((w * two_pow_112) * raw).to_bits(),
                (w * value).to_bits(),
                "{bits:#06x} {w}"
            );
        }
    }
}

#[test]
fn load_raw_times_its_gain_is_the_value_and_off_arm_never_subnormal() {
    // Whatever this target's raw exponent e, load_raw·2^e is the value
    // and (w·2^e)·load_raw is w·value bit for bit, so the walks' products
    // are the device's. Off Arm the widening is never a binary32
    // subnormal: x86 cores take a microcode assist per subnormal operand.
    let e = <f32 as Real>::raw_exponent::<f16>();
    assert_eq!(e, if cfg!(target_arch = "arm") { 112 } else { 0 });
    let gain = f32::exp2i(e);
    for bits in (0..0x7C00u16).chain(0x8000..0xFC00u16) {
        let raw = <f32 as Real>::load_raw(f16::from_bits(bits));
        let value = f16::from_bits(bits).to_f32();
        assert_eq!((raw * gain).to_bits(), value.to_bits(), "{bits:#06x}");
        assert_eq!(
            fvr_core::num::f16_bits_to_f32_finite(bits).to_bits(),
            value.to_bits(),
            "{bits:#06x}"
        );
        assert_eq!(
            fvr_core::num::f16_bits_to_f32(bits).to_bits(),
            value.to_bits(),
            "{bits:#06x}"
        );
        if !cfg!(target_arch = "arm") {
            assert!(raw == 0.0 || raw.is_normal(), "{bits:#06x}: {raw:e}");
        }
        for w in [0.3f32, -1.7e-3, 0.999_999_9] {
            assert_eq!(
                ((w * gain) * raw).to_bits(),
                (w * value).to_bits(),
                "{bits:#06x} {w}"
            );
        }
    }
    // Formats without a raw form widen as usual, with exponent 0.
    assert_eq!(<f32 as Real>::raw_exponent::<f32>(), 0);
    assert_eq!(<f64 as Real>::raw_exponent::<f16>(), 0);
}

#[test]
fn f32_floor_i64_equals_libm_floor_on_a_dense_sweep_and_the_edges() {
    let check = |x: f32| {
        assert_eq!(
            Real::floor_i64(x),
            libm::floorf(x) as i64,
            "{x:e} ({:#010x})",
            x.to_bits()
        );
    };
    // Every 251st bit pattern (positive and negative, all exponents).
    for bits in (0..=u32::MAX).step_by(251) {
        check(f32::from_bits(bits));
    }
    for x in [
        0.0,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -1.0,
        -1.5,
        2.5,
        -2.5,
        1e-45,
        -1e-45,
        16_777_215.0,
        16_777_216.0,
        -16_777_217.0,
        2_147_483_520.0,
        -2_147_483_520.0,
        2_147_483_648.0,
        -2_147_483_648.0,
        1e30,
        -1e30,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        f32::EPSILON,
        -f32::EPSILON,
    ] {
        check(x);
    }
}
