//! The storage codecs of `fvr_core::format` over every bit pattern: round
//! trips, ordering against f64, rounding to nearest even, overflow and
//! underflow; and bit-identity of the generic minifloat with `half`'s f16 and
//! bf16.

use fvr_core::num::Sample;
use fvr_core::num::{
    bf16, Arithmetic, BlockLayout, Blocking, FloatLayout, Format, FormatName, Minifloat16,
    Minifloat8, Q15, Q7,
};
use fvr_core::Error;
use half::f16;

/// Every check of one IEEE-style layout of `bits` bits, through `S`.
fn check_float_codec<S: Sample>(layout: FloatLayout, bits: u32, make: impl Fn(u32) -> S) {
    let m = layout.mantissa;
    let sign = 1u32 << (bits - 1);
    let inf = ((1u32 << layout.exponent) - 1) << m;
    // Decoding and re-encoding every non-NaN pattern is the identity, from
    // f64 and from f32.
    for b in 0..(1u32 << bits) {
        let s = make(b);
        let v = s.to_f64();
        let is_nan = (b & !sign) > inf;
        assert_eq!(v.is_nan(), is_nan, "{} {b:#x}", S::NAME);
        assert_eq!(s.is_finite(), (b & !sign) < inf, "{} {b:#x}", S::NAME);
        if is_nan {
            assert!(S::from_f64(v).to_f64().is_nan());
            continue;
        }
        assert_eq!(s.to_f32() as f64, v, "{} {b:#x}: f32 decode exact", S::NAME);
        assert_eq!(S::from_f64(v), s, "{} {b:#x} via f64", S::NAME);
        assert_eq!(S::from_f32(v as f32), s, "{} {b:#x} via f32", S::NAME);
        // Sign symmetry.
        if b & sign == 0 {
            assert_eq!(make(b | sign).to_f64(), -v, "{} {b:#x} negated", S::NAME);
        }
    }
    // Positive patterns 0..=inf decode strictly increasing; between each pair
    // of neighbours the midpoint rounds to the even one and points a quarter
    // of the gap inside round to the nearer one.
    for b in 0..inf {
        let (lo, hi) = (make(b).to_f64(), make(b + 1).to_f64());
        assert!(lo < hi, "{} not increasing at {b:#x}", S::NAME);
        if b + 1 == inf {
            // Overflow: from half an ulp above the maximum, values are infinite.
            let ulp = lo - make(b - 1).to_f64();
            assert_eq!(
                S::from_f64(lo + 0.5 * ulp),
                make(inf),
                "{} overflow",
                S::NAME
            );
            assert_eq!(S::from_f64(lo + 0.49 * ulp), make(b), "{} max", S::NAME);
            assert_eq!(S::MAX_FINITE, lo, "{} MAX_FINITE", S::NAME);
            continue;
        }
        let mid = 0.5 * (lo + hi);
        let even = if b % 2 == 0 { b } else { b + 1 };
        assert_eq!(S::from_f64(mid), make(even), "{} midpoint {b:#x}", S::NAME);
        assert_eq!(
            S::from_f64(-mid),
            make(even | sign),
            "{} -midpoint",
            S::NAME
        );
        let q = 0.25 * (hi - lo);
        assert_eq!(S::from_f64(mid - q), make(b), "{} below {b:#x}", S::NAME);
        assert_eq!(
            S::from_f64(mid + q),
            make(b + 1),
            "{} above {b:#x}",
            S::NAME
        );
    }
    // Underflow: half the smallest subnormal rounds to zero (even), anything
    // above it to the smallest subnormal; −0 keeps its sign.
    let tiny = make(1).to_f64();
    assert_eq!(S::from_f64(0.5 * tiny), make(0));
    assert_eq!(S::from_f64(0.500_001 * tiny), make(1));
    assert_eq!(S::from_f64(-0.0), make(sign));
    assert_eq!(S::from_f64(f64::INFINITY), make(inf));
    assert_eq!(S::from_f64(f64::NEG_INFINITY), make(inf | sign));
    // The scaling rule's largest intermediate, 2^(t+1), fits, and t is the
    // largest such value up to 14.
    let t = S::SCALE_LOG2;
    assert!(2f64.powi(t + 1) <= S::MAX_FINITE, "{}", S::NAME);
    assert!(t == 14 || 2f64.powi(t + 2) > S::MAX_FINITE, "{}", S::NAME);
}

/// [`check_float_codec`] for each exponent width `E` of a minifloat type.
macro_rules! check_splits {
    ($ty:ident, $bits:ty, $width:expr; $($e:literal),+) => {
        $(check_float_codec($ty::<$e>::LAYOUT, $width, |b| $ty::<$e>(b as $bits));)+
    };
}

#[test]
fn every_16_bit_minifloat_split_round_trips_orders_and_rounds_to_nearest_even() {
    check_splits!(Minifloat16, u16, 16; 2, 3, 4, 5, 6, 7, 8);
}

#[test]
fn every_8_bit_minifloat_split_round_trips_orders_and_rounds_to_nearest_even() {
    check_splits!(Minifloat8, u8, 8; 2, 3, 4, 5);
    assert_eq!(<Minifloat8<4> as Sample>::MAX_FINITE, 240.0);
    assert_eq!(<Minifloat8<5> as Sample>::MAX_FINITE, 57344.0);
}

#[test]
fn bf16_passes_the_same_codec_checks() {
    check_float_codec(Minifloat16::<8>::LAYOUT, 16, |b| bf16::from_bits(b as u16));
    check_float_codec(Minifloat16::<5>::LAYOUT, 16, |b| f16::from_bits(b as u16));
}

/// The generic codec with E = 5 is IEEE binary16 and with E = 8 bfloat16:
/// the same value for every pattern, and the same rounding at every
/// midpoint and quarter point between neighbours.
#[test]
fn minifloat_e5m10_is_f16_and_e8m7_is_bf16_bit_for_bit() {
    for b in 0..=u16::MAX {
        let (h, m) = (f16::from_bits(b), Minifloat16::<5>(b));
        let (g, n) = (bf16::from_bits(b), Minifloat16::<8>(b));
        if h.is_nan() {
            assert!(m.to_f64().is_nan());
        } else {
            assert_eq!(h.to_f64(), m.to_f64(), "{b:#06x}");
        }
        if g.is_nan() {
            assert!(n.to_f64().is_nan());
        } else {
            assert_eq!(g.to_f64(), n.to_f64(), "{b:#06x}");
        }
    }
    for b in 0..0x7bffu16 {
        let (lo, hi) = (f16::from_bits(b).to_f64(), f16::from_bits(b + 1).to_f64());
        for v in [0.5 * (lo + hi), lo + 0.3 * (hi - lo), lo + 0.7 * (hi - lo)] {
            assert_eq!(Minifloat16::<5>::from_f64(v).0, f16::from_f64(v).to_bits());
            let v32 = v as f32;
            assert_eq!(
                Minifloat16::<5>::from_f32(v32).0,
                f16::from_f32(v32).to_bits()
            );
        }
    }
    for b in 0..0x7f7fu16 {
        let (lo, hi) = (bf16::from_bits(b).to_f64(), bf16::from_bits(b + 1).to_f64());
        for v in [0.5 * (lo + hi), lo + 0.3 * (hi - lo), lo + 0.7 * (hi - lo)] {
            let v32 = v as f32;
            assert_eq!(
                Minifloat16::<8>::from_f32(v32).0,
                bf16::from_f32(v32).to_bits()
            );
        }
    }
}

/// Q15 and Q7: every pattern round-trips, values are ordered, the reserved
/// most negative pattern flags overflow, rounding is to nearest even.
#[test]
fn q15_and_q7_fractions_round_trip_order_and_flag_overflow() {
    let mut last = f64::NEG_INFINITY;
    for i in i16::MIN + 1..=i16::MAX {
        let q = Q15(i);
        let v = q.to_f64();
        assert_eq!(v, i as f64 / 32768.0);
        assert_eq!(q.to_f32() as f64, v);
        assert!(v > last);
        last = v;
        assert_eq!(Q15::from_f64(v), q);
        assert_eq!(Q15::from_f32(v as f32), q);
        assert!(q.is_finite());
        if i < i16::MAX {
            let mid = v + 0.5 / 32768.0;
            let even = if i % 2 == 0 { i } else { i + 1 };
            assert_eq!(Q15::from_f64(mid), Q15(even), "midpoint above {i}");
        }
    }
    assert!(!Q15(i16::MIN).is_finite());
    assert!(!Q15::from_f64(1.0).is_finite());
    assert!(!Q15::from_f64(-1.0).is_finite());
    assert!(!Q15::from_f64(f64::NAN).is_finite());
    assert!(Q15::from_f64(32767.49 / 32768.0).is_finite());
    for i in i8::MIN + 1..=i8::MAX {
        let q = Q7(i);
        assert_eq!(Q7::from_f64(q.to_f64()), q);
        assert_eq!(q.to_f32() as f64, i as f64 / 128.0);
    }
    assert!(!Q7(i8::MIN).is_finite());
    assert!(!Q7::from_f64(1.0).is_finite());
    for s in [Q15::SCALE_LOG2, Q7::SCALE_LOG2] {
        assert!(2f64.powi(s + 1) <= Q7::MAX_FINITE);
    }
}

#[test]
fn a_minifloat_split_that_does_not_add_up_is_a_named_error() {
    let err = Format::minifloat(5, 11).unwrap_err();
    assert_eq!(
        err,
        Error::BadMinifloatSplit {
            exponent: 5,
            mantissa: 11
        }
    );
    let msg = err.to_string();
    assert!(msg.contains("e5m11") && msg.contains("17 bits"), "{msg}");
    assert!(Format::minifloat(u32::MAX, u32::MAX).is_err());
    assert_eq!(Format::minifloat(5, 10), Ok(Format::F16));
    assert_eq!(Format::minifloat(8, 7), Ok(Format::Bf16));
    assert_eq!(Format::minifloat(4, 11), Ok(Format::Minifloat16(4)));
    assert_eq!(Format::minifloat(4, 3), Ok(Format::Minifloat8(4)));
    // Too few or too many exponent bits for the target: clear errors.
    for (e, m) in [(1, 14), (9, 6), (0, 15), (6, 1), (1, 6)] {
        let err = Format::minifloat(e, m).unwrap_err();
        assert!(
            matches!(err, Error::UnsupportedFormat { .. }),
            "e{e}m{m}: {err}"
        );
    }
    assert!(Format::minifloat(9, 6)
        .unwrap_err()
        .to_string()
        .contains("f32"));
}

#[test]
fn a_block_size_that_does_not_divide_the_line_is_a_named_error() {
    let err = BlockLayout::Brick(6).exponent_count(64).unwrap_err();
    assert_eq!(err, Error::BlockSizeMismatch { block: 6, line: 64 });
    assert!(err.to_string().contains("block size 6 does not divide"));
    assert!(BlockLayout::Brick(0).exponent_count(64).is_err());
    assert_eq!(BlockLayout::Brick(8).exponent_count(64), Ok(512));
    assert_eq!(BlockLayout::Line.exponent_count(64), Ok(4096));
    let q = Format::Q15(Blocking::Blocks(BlockLayout::Brick(6)));
    assert!(matches!(
        q.check(Arithmetic::HostOnce, 64),
        Err(Error::BlockSizeMismatch { .. })
    ));
}

#[test]
fn formats_the_target_cannot_prepare_are_refused_at_configuration() {
    // Per-line exponents follow the passes in place; brick exponents cannot.
    let line = Format::Q15(Blocking::Blocks(BlockLayout::Line));
    let brick = Format::Q7(Blocking::Blocks(BlockLayout::Brick(4)));
    for a in Arithmetic::ALL {
        assert!(line.check(a, 64).is_ok());
    }
    assert!(brick.check(Arithmetic::HostOnce, 64).is_ok());
    for a in [Arithmetic::PerPass, Arithmetic::PerStage] {
        let err = brick.check(a, 64).unwrap_err();
        assert!(err.to_string().contains("host-once"), "{err}");
    }
    assert!(Format::F64.check(Arithmetic::PerStage, 64).is_err());
    assert!(Format::F64.check(Arithmetic::HostOnce, 64).is_err());
    assert!(Format::Q15(Blocking::Volume)
        .check(Arithmetic::PerStage, 64)
        .is_ok());
}

#[test]
fn format_names_and_bytes_per_voxel() {
    let cases = [
        (Format::F16, "f16", 2.0),
        (Format::Bf16, "bf16", 2.0),
        (Format::Minifloat16(4), "e4m11", 2.0),
        (Format::Minifloat8(4), "e4m3", 1.0),
        (Format::Q15(Blocking::Volume), "q15", 2.0),
        (
            Format::Q15(Blocking::Blocks(BlockLayout::Line)),
            "q15-line",
            2.0 + 1.0 / 64.0,
        ),
        (
            Format::Q7(Blocking::Blocks(BlockLayout::Brick(4))),
            "q7-brick4",
            1.0 + 1.0 / 64.0,
        ),
        (Format::F64, "f64", 8.0),
    ];
    for (f, name, bytes) in cases {
        assert_eq!(FormatName(f).to_string(), name);
        assert_eq!(f.bytes_per_voxel(64), bytes, "{name}");
    }
}

/// Q15 block floating point prepared in place, one exponent per line: the
/// input and each of the three passes store every line with its own
/// exponent, and a final pass re-blocks into x-lines: five roundings, each
/// of at most half a step `2^-16·max|line|`, i.e. relative RMS at most
/// `2^-15·√n/√12` of the line (max ≤ ‖line‖). The DHT scales signal and
/// error alike, so the spectrum's relative RMS error stays within
/// `√5·2^-15·√n/√12` of the same pipeline in f64.
#[test]
fn q15_line_blocks_prepared_in_place_match_the_f64_spectrum_within_five_roundings() {
    use fvr_core::dht::{Rounding, Twiddles};
    use fvr_core::filter::{Filter, FilterKind};
    use fvr_core::spectrum::{prepare_scratch_len, LineBlockStorage, Spectrum};
    use fvr_core::volume::DenseVolume;
    let n = 16usize;
    let mut lcg = fvr_tests::Lcg(7);
    let data: Vec<f32> = (0..n * n * n)
        .map(|_| (lcg.next_u64() >> 40) as f32 / (1u64 << 24) as f32 - 0.3)
        .collect();
    let source = DenseVolume::new([n; 3], &data).unwrap();
    let filter = Filter::new(FilterKind::Kb4, 2).unwrap();
    let grid = 32;
    let mut tw64 = vec![0.0f64; Twiddles::<f64>::buffer_len(grid)];
    let tw64 = Twiddles::new(&mut tw64, grid).unwrap();
    let mut s64 = vec![0.0f64; prepare_scratch_len(grid)];
    let mut ref_data = vec![0.0f64; grid * grid * grid];
    let reference = Spectrum::prepare(&source, filter, &mut ref_data, &mut s64, &tw64).unwrap();
    let mut tw32 = vec![0.0f32; Twiddles::<f32>::buffer_len(grid)];
    let tw32 = Twiddles::new(&mut tw32, grid).unwrap();
    let mut s32 = vec![0.0f32; prepare_scratch_len(grid)];
    let bound = 5f64.sqrt() * 2f64.powi(-15) * (grid as f64).sqrt() / 12f64.sqrt();
    for rounding in [Rounding::PerPass, Rounding::PerStage] {
        let mut m = vec![Q15::default(); grid * grid * grid];
        let (mut e, mut e2) = (vec![0i8; grid * grid], vec![0i8; grid * grid]);
        let spec = Spectrum::prepare_line_blocks(
            &source,
            filter,
            LineBlockStorage {
                mantissas: &mut m,
                exponents: &mut e,
                exponent_scratch: &mut e2,
            },
            &mut s32,
            &tw32,
            rounding,
        )
        .unwrap();
        assert!(spec.blocks().is_some());
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..grid * grid * grid {
            let r = reference.value(i) / reference.scale();
            let q = spec.value(i) / spec.scale();
            num += (q - r) * (q - r);
            den += r * r;
        }
        let rel = (num / den).sqrt();
        let limit = if rounding == Rounding::PerPass {
            bound
        } else {
            // Per stage: log2(32) = 5 more roundings in each of 3 passes.
            bound * (20f64 / 5.0).sqrt()
        };
        assert!(
            rel <= limit,
            "{rounding:?}: relative RMS {rel:e} > {limit:e}"
        );
    }
}

/// Every 16-bit pattern of f16 and bf16 round-trips through
/// `Sample::from_pattern16` and `Sample::pattern16` to the same value;
/// wider formats have none.
#[test]
fn sixteen_bit_patterns_round_trip_exhaustively() {
    for p in 0..=u16::MAX {
        let h = <half::f16 as Sample>::from_pattern16(p).unwrap();
        assert_eq!(h.to_bits(), p);
        assert_eq!(h.pattern16(), Some(p));
        let b = <half::bf16 as Sample>::from_pattern16(p).unwrap();
        assert_eq!(b.to_bits(), p);
        assert_eq!(b.pattern16(), Some(p));
    }
    assert_eq!(1.5f32.pattern16(), None);
    assert_eq!(<f64 as Sample>::from_pattern16(7), None);
}
