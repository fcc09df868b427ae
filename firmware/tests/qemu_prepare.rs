//! The spectra prepared on the device (`fvr-prepare` on the Cortex-M4F,
//! 32³; `fvr-prepare-m7` on the Cortex-M7, 64³) and the views rendered from
//! them, against the host:
//! - bit for bit against the same core code on the host
//!   ([`prepare_and_render`], and `OwnedSpectrum::prepare_in_place`, the
//!   host's wrapper of it), since the arithmetic is the same;
//! - in dB against the host's fast preparation (FFT, f16 rounded once) and
//!   the f64 pipeline, whose arithmetic differs.
//!
//! The QEMU comparison needs the firmware's outputs, so it is ignored in
//! `cargo test` and run by `scripts/firmware.sh` as
//! `FVR_QEMU_OUT=<dir> cargo test -p fvr-firmware --test qemu_prepare -- --ignored`.

mod common;

use std::path::Path;

use common::{below_floors, count_differing, qemu_out_dir, read_output, NoClock};
use fvr_core::f16;
use fvr_engine::spectrum::{AnySpectrum, OwnedSpectrum};
use fvr_engine::volume::Volume;
use fvr_firmware::prepare::{
    fnv1a_f16, prepare_and_render, scratch_len, spectrum_len, view_lens, PrepBuffers, PrepInput,
    PREP_32, PREP_64,
};
use fvr_firmware::scene::VIEW;
use fvr_firmware::stored::twiddles;
use fvr_host::io::nrrd::parse_nrrd;
use fvr_host::reference::snr_db;

/// The unit roundoff of f16.
const U: f64 = 1.0 / 2048.0;

/// The SNR of one rounding to f16 of values spread over their binades,
/// `10·log10(3/u²)` (71.3 dB).
fn one_rounding_db() -> f64 {
    10.0 * (3.0 / (U * U)).log10()
}

/// The device's spectrum is rounded to f16 after each of the three passes;
/// each pass is orthogonal up to a scale, so the three roundings' errors add
/// in energy: 3 times one rounding's, less 1 dB of margin.
fn per_pass_floor_db() -> f64 {
    one_rounding_db() - 10.0 * 3f64.log10() - 1.0
}

/// Against the fast preparation (one rounding) the errors of both add: 4
/// roundings' energy, less 1 dB.
fn against_fast_floor_db() -> f64 {
    one_rounding_db() - 10.0 * 4f64.log10() - 1.0
}

/// The device program on the host: the spectrum (side `N`) and the image.
fn host_run<const N: usize>(input: &PrepInput) -> (Vec<f16>, Vec<f32>, f64) {
    let mut spectrum = vec![f16::ZERO; spectrum_len(N)];
    let mut scratch = vec![0.0f32; scratch_len(N)];
    let (g, a) = view_lens(N);
    let (mut grid, mut aux) = (vec![0.0f32; g], vec![0.0f32; a]);
    let tw = twiddles().unwrap();
    let prepared = prepare_and_render::<N, _>(
        input,
        &tw,
        &mut PrepBuffers {
            spectrum: &mut spectrum,
            scratch: &mut scratch,
            grid: &mut grid,
            aux: &mut aux,
        },
        &NoClock,
    )
    .unwrap();
    grid.truncate(N * N);
    (spectrum, grid, prepared.scale)
}

fn host_volume(input: &PrepInput) -> Volume {
    Volume::new(
        input.dims(),
        input.voxels.iter().map(|&v| v as f32).collect(),
    )
}

/// `−20·log10` of the relative RMS distance of `a/scale_a` to `reference`.
fn spectrum_db(a: &[f16], scale_a: f64, reference: &OwnedSpectrum<f64>) -> f64 {
    let (mut err, mut sig) = (0.0f64, 0.0f64);
    for (x, y) in a.iter().zip(reference.data()) {
        let (x, y) = (x.to_f64() / scale_a, y / reference.scale());
        err += (x - y) * (x - y);
        sig += y * y;
    }
    10.0 * (sig / err).log10()
}

/// What the host's other preparations give for `input`: the image of the
/// fast f16 preparation, the f64 spectrum and its image.
struct References {
    fast_image: Vec<f64>,
    f64_spectrum: OwnedSpectrum<f64>,
    f64_image: Vec<f64>,
}

fn references(input: &PrepInput) -> References {
    let volume = host_volume(input);
    let filter = input.filter().unwrap();
    let n = input.side;
    let fast = AnySpectrum::F16(OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap());
    let f64_spectrum = OwnedSpectrum::<f64>::prepare_in_place::<f64>(&volume, filter).unwrap();
    let f64_image = AnySpectrum::F64(f64_spectrum.clone())
        .render(&VIEW, n, n)
        .unwrap();
    References {
        fast_image: fast.render(&VIEW, n, n).unwrap(),
        f64_spectrum,
        f64_image,
    }
}

/// The dB figures of a device-path result and their floors; `Err` names
/// the figures below their floor.
fn check_db(
    what: &str,
    spectrum: &[f16],
    scale: f64,
    image: &[f32],
    r: &References,
) -> Vec<String> {
    let image: Vec<f64> = image.iter().map(|&v| v as f64).collect();
    let figures = [
        (
            "spectrum vs f64",
            spectrum_db(spectrum, scale, &r.f64_spectrum),
            per_pass_floor_db(),
        ),
        (
            "image vs f64",
            snr_db(&r.f64_image, &image),
            per_pass_floor_db(),
        ),
        (
            "image vs fast host preparation",
            snr_db(&r.fast_image, &image),
            against_fast_floor_db(),
        ),
    ];
    below_floors(what, &figures)
}

/// The host's in-place preparation of the same u8 volume equals the device
/// program's preparation bit for bit: same core code, same twiddles.
fn in_place_wrapper_agrees<const N: usize>(input: &PrepInput) {
    let (spectrum, _, scale) = host_run::<N>(input);
    let wrapper =
        OwnedSpectrum::<f16>::prepare_in_place::<f32>(&host_volume(input), input.filter().unwrap())
            .unwrap();
    assert_eq!(wrapper.scale(), scale);
    let differing = count_differing(&spectrum, wrapper.data(), f16::to_bits);
    assert_eq!(differing, 0, "side {N}: {differing} coefficients differ");
}

#[test]
fn device_program_on_the_host_is_the_in_place_preparation() {
    in_place_wrapper_agrees::<32>(&PREP_32);
}

#[test]
fn device_path_meets_the_per_pass_rounding_floors() {
    let (spectrum, image, scale) = host_run::<32>(&PREP_32);
    let failures = check_db(
        "host, side 32",
        &spectrum,
        scale,
        &image,
        &references(&PREP_32),
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

/// One program's outputs against the host: bit for bit, then in dB.
fn compare_program<const N: usize>(dir: &Path, program: &str, input: &PrepInput) -> Vec<String> {
    let (host_spectrum, host_image, scale) = host_run::<N>(input);
    let mut failures = Vec::new();

    let name = format!("{program}-spectrum.f16");
    let bytes = read_output(dir, &name);
    assert_eq!(bytes.len(), 2 * spectrum_len(N), "{name}");
    let device_spectrum: Vec<f16> = bytes
        .chunks_exact(2)
        .map(|b| f16::from_bits(u16::from_le_bytes([b[0], b[1]])))
        .collect();
    let differing = count_differing(&device_spectrum, &host_spectrum, f16::to_bits);
    println!(
        "{program}: side {N}, spectrum fnv1a {:#010x}, {differing} of {} coefficients differ from the host core",
        fnv1a_f16(&device_spectrum),
        device_spectrum.len()
    );
    if differing != 0 {
        failures.push(format!(
            "{program}: {differing} spectrum coefficients differ"
        ));
    }

    let path = dir.join(format!("{program}-image.nrrd"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let device = parse_nrrd(&bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(device.dims, [N, N, 1], "{}", path.display());
    let differing = count_differing(&device.data, &host_image, f32::to_bits);
    println!(
        "{program}: {differing} of {} pixels differ from the host core",
        N * N
    );
    if differing != 0 {
        failures.push(format!("{program}: {differing} pixels differ"));
    }
    failures.extend(check_db(
        program,
        &device_spectrum,
        scale,
        &device.data,
        &references(input),
    ));
    failures
}

#[test]
#[ignore = "needs the firmware's QEMU outputs: bash scripts/firmware.sh"]
fn qemu_prepared_spectra_equal_host_bit_for_bit() {
    let dir = qemu_out_dir();
    let dir = dir.as_path();
    let mut failures = compare_program::<32>(dir, "fvr-prepare", &PREP_32);
    failures.extend(compare_program::<64>(dir, "fvr-prepare-m7", &PREP_64));
    assert!(failures.is_empty(), "{failures:#?}");
}
