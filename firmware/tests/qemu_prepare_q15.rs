//! The Q15 spectra prepared in integers on the device (`fvr-prepare-q15`:
//! 32³ on the Cortex-M4F, 64³ on the Cortex-M3; `fvr-prepare-q15-m7`: 64³
//! on the Cortex-M7) and the integer views rendered from them, against the
//! host:
//! - bit for bit against the same core code on the host
//!   ([`prepare_and_render_q15`]): spectrum mantissas, exponents, image
//!   and its exponent;
//! - in dB against the f64 pipeline (spectrum and view) and against the
//!   view of the host-prepared f16 spectrum (the fast preparation).
//!
//! # Floors
//! The Q15 model of `dht::fixed`: `6.02·12 + 7.78 − 10·log10 L −
//! 20·log10 κ` dB. The spectrum rounds `L = 3·log₂n + 5` times (the
//! transform's stages and correction, the input's rounding to Q15, the
//! three premultipliers); κ is the crest factor of the f64 spectrum, the
//! most concentrated stage of a volume's transform. The view adds the
//! integer view's `2·log₂n + 4` roundings (`tests/common/fixed.rs`) and
//! the image's crest factor. Against the f16 view the f16 path's own error
//! (one rounding to f16, 71.3 dB, less 1 dB) adds in energy. The views must also meet the 40 dB the integer view is held to
//! against f64.
//!
//! The QEMU comparison needs the firmware's outputs, so it is ignored in
//! `cargo test` and run by `scripts/firmware.sh` as
//! `FVR_QEMU_OUT=<dir> cargo test -p fvr-firmware --test qemu_prepare_q15 -- --ignored`.

mod common;

use std::path::Path;

use common::{below_floors, qemu_out_dir, read_output, NoClock};
use fvr_core::f16;
use fvr_core::num::Q15;
use fvr_core::slice::fixed::FixedPhases;
use fvr_core::spectrum::Q15Storage;
use fvr_engine::spectrum::{AnySpectrum, OwnedSpectrum};
use fvr_engine::volume::Volume;
use fvr_firmware::prepare::{PrepInput, PREP_32, PREP_64};
use fvr_firmware::prepare_q15::{
    fnv1a_q15, prepare_and_render_q15, q15_lens, twiddles_i16, twiddles_q15, Q15Buffers,
    TWIDDLES_LEN, WIDTH,
};
use fvr_firmware::scene::VIEW;
use fvr_host::reference::snr_db;

/// The goal of the integer view against the f64 pipeline.
const VIEW_GOAL_DB: f64 = 40.0;

/// The f16 view's error against f64: one rounding to f16 (the fast
/// preparation), `10·log10(3/u²)` for `u = 2^−11`, less 1 dB.
fn f16_path_db() -> f64 {
    10.0 * (3.0 * 2048.0 * 2048.0f64).log10() - 1.0
}

/// A Q15 spectrum and image, from the host or the device.
#[derive(PartialEq)]
struct Q15Run {
    exponents: Vec<i8>,
    mantissas: Vec<i16>,
    image_exponent: i32,
    image: Vec<i16>,
}

/// The device program on the host, with its spectrum's scale.
fn host_run<const N: usize>(input: &PrepInput) -> (Q15Run, f64) {
    let (cube, lines, premul, grid, aux) = q15_lens(N);
    let mut mantissas = vec![Q15(0); cube];
    let mut exponents = vec![0i8; lines];
    let mut premul = vec![0i32; premul];
    let (mut grid, mut aux) = (vec![0i32; grid], vec![0i32; aux]);
    let mut block = vec![0i16; N * N];
    let mut tw_buf = [Q15(0); TWIDDLES_LEN];
    let tw_data = twiddles_q15(&mut tw_buf).unwrap();
    let tw_view = twiddles_i16().unwrap();
    let mut phases = Box::new(FixedPhases::<WIDTH>::new());
    phases
        .fill_from(input.filter().unwrap(), input.kernel)
        .unwrap();
    let prepared = prepare_and_render_q15::<N, _>(
        input,
        (&tw_data, &tw_view),
        &phases,
        &mut Q15Buffers {
            storage: Q15Storage {
                mantissas: &mut mantissas,
                exponents: &mut exponents,
                premul: &mut premul,
            },
            grid: &mut grid,
            aux: &mut aux,
            block: &mut block,
        },
        &NoClock,
    )
    .unwrap();
    (
        Q15Run {
            exponents,
            mantissas: mantissas.iter().map(|m| m.0).collect(),
            image_exponent: prepared.image_exponent,
            image: block[..N * N].to_vec(),
        },
        prepared.scale,
    )
}

fn crest(v: &[f64]) -> f64 {
    let peak = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    peak / rms
}

fn model_floor_db(roundings: f64, crest: f64) -> f64 {
    6.0206 * 12.0 + 10.0 * 6f64.log10() - 10.0 * roundings.log10() - 20.0 * crest.log10()
}

/// The f64 spectrum (as `H`) and view, and the f16 spectrum's view.
struct References {
    f64_spectrum: Vec<f64>,
    f64_image: Vec<f64>,
    f16_image: Vec<f64>,
}

fn references(input: &PrepInput) -> References {
    let volume = Volume::new(
        input.dims(),
        input.voxels.iter().map(|&v| v as f32).collect(),
    );
    let filter = input.filter().unwrap();
    let n = input.side;
    let f16 = AnySpectrum::F16(OwnedSpectrum::<f16>::prepare::<f32>(&volume, filter).unwrap());
    let f64_spectrum = OwnedSpectrum::<f64>::prepare_in_place::<f64>(&volume, filter).unwrap();
    let scale = f64_spectrum.scale();
    References {
        f64_spectrum: f64_spectrum.data().iter().map(|v| v / scale).collect(),
        f64_image: AnySpectrum::F64(f64_spectrum).render(&VIEW, n, n).unwrap(),
        f16_image: f16.render(&VIEW, n, n).unwrap(),
    }
}

/// The dB figures of a Q15 result (side `n`, scale `scale`) and their
/// floors; the failures, by name.
fn check_db(what: &str, run: &Q15Run, n: usize, scale: f64, r: &References) -> Vec<String> {
    let spectrum: Vec<f64> = run
        .mantissas
        .chunks_exact(n)
        .zip(&run.exponents)
        .flat_map(|(line, &e)| {
            let unit = (e as f64 - 15.0).exp2() / scale;
            line.iter().map(move |&m| m as f64 * unit)
        })
        .collect();
    let unit = (run.image_exponent as f64).exp2();
    let image: Vec<f64> = run.image.iter().map(|&m| m as f64 * unit).collect();
    let bits = n.trailing_zeros() as f64;
    let spectrum_roundings = 3.0 * bits + 5.0;
    let kappa = crest(&r.f64_spectrum);
    let spectrum_floor = model_floor_db(spectrum_roundings, kappa);
    let view_floor = model_floor_db(
        spectrum_roundings + 2.0 * bits + 4.0,
        kappa.max(crest(&r.f64_image)),
    );
    // The two paths' errors add in energy.
    let against_f16_floor =
        -10.0 * (10f64.powf(-view_floor / 10.0) + 10f64.powf(-f16_path_db() / 10.0)).log10();
    let image_vs_f64 = snr_db(&r.f64_image, &image);
    let figures = [
        (
            "spectrum vs f64",
            snr_db(&r.f64_spectrum, &spectrum),
            spectrum_floor,
        ),
        ("image vs f64", image_vs_f64, view_floor),
        ("image vs f64 (goal)", image_vs_f64, VIEW_GOAL_DB),
        (
            "image vs the f16 spectrum's view",
            snr_db(&r.f16_image, &image),
            against_f16_floor,
        ),
    ];
    below_floors(what, &figures)
}

#[test]
fn device_program_on_the_host_meets_the_floors() {
    let (run, scale) = host_run::<32>(&PREP_32);
    let failures = check_db("host, side 32", &run, 32, scale, &references(&PREP_32));
    assert!(failures.is_empty(), "{failures:#?}");
}

/// One program's outputs against the host: bit for bit, then in dB.
fn compare_program<const N: usize>(dir: &Path, program: &str, input: &PrepInput) -> Vec<String> {
    let (host, scale) = host_run::<N>(input);
    let bytes = read_output(dir, &format!("{program}-spectrum.q15"));
    assert_eq!(bytes.len(), N * N + 2 * N * N * N, "{program}-spectrum.q15");
    let (exps, mants) = bytes.split_at(N * N);
    let image_bytes = read_output(dir, &format!("{program}-image.q15"));
    assert_eq!(image_bytes.len(), 4 + 2 * N * N, "{program}-image.q15");
    let le16 = |b: &[u8]| -> Vec<i16> {
        b.chunks_exact(2)
            .map(|b| i16::from_le_bytes([b[0], b[1]]))
            .collect()
    };
    let device = Q15Run {
        exponents: exps.iter().map(|&b| b as i8).collect(),
        mantissas: le16(mants),
        image_exponent: i32::from_le_bytes(image_bytes[..4].try_into().unwrap()),
        image: le16(&image_bytes[4..]),
    };
    let differing = |a: &[i16], b: &[i16]| a.iter().zip(b).filter(|(x, y)| x != y).count();
    let (spectrum_diff, image_diff) = (
        differing(&device.mantissas, &host.mantissas),
        differing(&device.image, &host.image),
    );
    let exps_diff = device
        .exponents
        .iter()
        .zip(&host.exponents)
        .filter(|(a, b)| a != b)
        .count();
    let mantissas: Vec<Q15> = device.mantissas.iter().map(|&m| Q15(m)).collect();
    println!(
        "{program}: side {N}, spectrum fnv1a {:#010x}, {spectrum_diff} of {} mantissas and \
         {exps_diff} of {} exponents differ from the host core; image exponent {} (host {}), \
         {image_diff} of {} pixels differ",
        fnv1a_q15(&mantissas, &device.exponents),
        N * N * N,
        N * N,
        device.image_exponent,
        host.image_exponent,
        N * N
    );
    let mut failures = Vec::new();
    if device != host {
        failures.push(format!("{program}: not bit-identical to the host core"));
    }
    failures.extend(check_db(program, &device, N, scale, &references(input)));
    failures
}

#[test]
#[ignore = "needs the firmware's QEMU outputs: bash scripts/firmware.sh"]
fn qemu_q15_spectra_equal_host_bit_for_bit() {
    let dir = qemu_out_dir();
    let dir = dir.as_path();
    let mut failures = compare_program::<32>(dir, "fvr-prepare-q15", &PREP_32);
    failures.extend(compare_program::<64>(dir, "fvr-prepare-q15-m7", &PREP_64));
    failures.extend(compare_program::<64>(dir, "fvr-prepare-q15-m3", &PREP_64));
    assert!(failures.is_empty(), "{failures:#?}");
}
