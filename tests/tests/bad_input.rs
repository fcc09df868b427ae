//! The core refuses bad data with named errors instead of panicking.

use fvr_core::dht::Twiddles;
use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::View;
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use fvr_core::volume::DenseVolume;
use fvr_core::Error;
use fvr_engine::spectrum::{AnySpectrum, OwnedSpectrum, Precision};
use fvr_engine::volume::Volume;
use fvr_host::reference::snr_db;
use half::f16;

/// Prepare `vol` into an f16 spectrum of `storage` elements with tables
/// for side `n`; the error, if any.
fn prepare_f16(
    vol: &DenseVolume<'_, f32>,
    filter: Filter,
    storage: usize,
    n: usize,
) -> Result<(), Error> {
    let mut storage = vec![f16::ZERO; storage];
    let mut scratch = vec![0.0f32; prepare_scratch_len(n)];
    let mut tw = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw, n).unwrap();
    Spectrum::prepare(vol, filter, &mut storage, &mut scratch, &tw).map(|_| ())
}

#[test]
fn nan_and_infinite_voxels_are_named_by_index() {
    let mut data = vec![1.0f32; 8 * 8 * 8];
    data[3 + 8 * (4 + 8 * 5)] = f32::INFINITY;
    let vol = DenseVolume::new([8, 8, 8], &data).unwrap();
    let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
    let err = prepare_f16(&vol, filter, 512, 8).unwrap_err();
    assert_eq!(
        err,
        Error::NonFiniteVoxel {
            index: [3, 4, 5],
            value: f64::INFINITY
        }
    );
    assert!(Filter::fit(FilterKind::Kb4, 1, &vol).is_err());
    // A core error travels as a standard error with its message intact.
    let boxed: Box<dyn std::error::Error> = Box::new(err);
    assert_eq!(boxed.to_string(), err.to_string());
    assert!(boxed.to_string().contains("voxel (3, 4, 5)"));
}

#[test]
fn full_range_volume_does_not_overflow_f16() {
    // 32³ of 65535: DC = 2.1e9, far beyond f16's 65504. The scaling rule must
    // keep every stored value finite and cost no precision: the f16 image
    // agrees with the f64 pipeline's to the f16 floor (≥ 70 dB). Oversampling
    // 2 keeps premultiplication well conditioned on this box-filling volume
    // (see `ill_conditioned_premultiplication_is_flagged`).
    let n = 32;
    let volume = Volume::filled([n, n, n], 65535.0);
    let filter = Filter::new(FilterKind::Kb4, 2).unwrap();
    let f16_spec = OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap();
    assert!(f16_spec.data().iter().all(|v| v.is_finite()));
    assert!(f16_spec.scale() < 1.0, "the DC must be scaled down");
    let view = View::along([1.0, 0.0, 0.0]);
    let image = AnySpectrum::F16(f16_spec).render(&view, n, n).unwrap();
    let reference = AnySpectrum::prepare(&volume, filter, Precision::F64)
        .unwrap()
        .render(&view, n, n)
        .unwrap();
    let snr = snr_db(&reference, &image);
    assert!(snr >= 70.0, "{snr:.2} dB");
}

#[test]
fn buffers_and_sizes_are_checked() {
    let data = vec![1.0f32; 27];
    assert!(matches!(
        DenseVolume::new([3, 3, 4], &data),
        Err(Error::LengthMismatch {
            expected: 36,
            got: 27,
            ..
        })
    ));
    assert_eq!(
        DenseVolume::new([0, 3, 3], &data[..0]).unwrap_err(),
        Error::EmptyVolume
    );
    let vol = DenseVolume::new([3, 3, 3], &data).unwrap();
    let filter = Filter::new(FilterKind::Linear, 1).unwrap();
    let err = prepare_f16(&vol, filter, 10, 4).unwrap_err();
    assert!(
        matches!(
            err,
            Error::BufferTooSmall {
                needed: 64,
                got: 10,
                ..
            }
        ),
        "{err}"
    );
    assert!(matches!(
        Filter::new(FilterKind::Kb4, 3),
        Err(Error::UnsupportedOversampling { factor: 3 })
    ));
}

/// Kaiser–Bessel at σ = 1 on a volume that fills its grid amplifies the
/// corners by about 10⁶ when premultiplying, and an f16 spectrum cannot hold
/// the rest: the storage estimate must say so (the CLI warns below 50 dB),
/// while a centred phantom passes.
#[test]
fn ill_conditioned_premultiplication_is_flagged() {
    let n = 32;
    let boxed = Volume::filled([n, n, n], 1.0);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let spec = AnySpectrum::prepare(&boxed, filter, Precision::F16).unwrap();
    let sum = (n * n * n) as f64;
    let estimate = spec.storage_snr_estimate_db(sum);
    assert!(estimate < 20.0, "box at σ=1: {estimate:.1} dB");
    let view = View::along([1.0, 0.0, 0.0]);
    let measured = snr_db(
        &AnySpectrum::prepare(&boxed, filter, Precision::F64)
            .unwrap()
            .render(&view, n, n)
            .unwrap(),
        &spec.render(&view, n, n).unwrap(),
    );
    assert!(
        measured < 20.0,
        "the flag is not a false alarm: {measured:.1} dB"
    );

    let phantom = fvr_engine::volume::phantom::GaussianMixture::random(1, n, 8);
    let volume = fvr_engine::volume::phantom::sample(&phantom, [n, n, n]);
    let sum: f64 = volume.data.iter().map(|&v| v as f64).sum();
    let spec = AnySpectrum::prepare(&volume, filter, Precision::F16).unwrap();
    assert!(spec.storage_snr_estimate_db(sum) > 70.0);
}

#[test]
fn check_finite_names_the_first_nan_or_infinite_coefficient() {
    let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
    let mut data = vec![f16::from_f32(0.25); 8 * 8 * 8];
    // A spectrum rebuilt from parts is not scanned per view...
    let spec = Spectrum::from_parts(&data, 8, 1.0, filter, [8, 8, 8]).unwrap();
    assert!(spec.check_finite().is_ok());
    // ...so data from elsewhere is checked once: the first bad index is named.
    data[77] = f16::NAN;
    data[300] = f16::INFINITY;
    let spec = Spectrum::from_parts(&data, 8, 1.0, filter, [8, 8, 8]).unwrap();
    let err = spec.check_finite().unwrap_err();
    assert!(
        matches!(err, Error::NonFiniteTableEntry { index: 77, .. }),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("spectrum coefficient entry 77"),
        "{err}"
    );
}
