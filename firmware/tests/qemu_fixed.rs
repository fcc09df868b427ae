//! The Cortex-M3's integer-only inverse 2D transforms (`fvr-fixed-bench`
//! under QEMU mps2-an385) against the host's, bit for bit: Q15 and Q31
//! mantissas and block exponents, and the soft-float f32 result. Each is
//! also measured against an f64 reference, the Q15 and Q31 ones against the
//! SNR floor of the error model of `fvr_core::dht::fixed` (stated in its
//! tests): `6.02·(F − 3) + 7.78 − 10·log10 L − 20·log10 κ` dB for `F`
//! fraction bits, `L` rounded stages and crest factor `κ`.
//!
//! The whole plain kb3 view too: the integer one
//! (`fvr_firmware::fixed_view`, exponent and Q15 mantissas) and the
//! soft-float f32 one (`fvr_firmware::frame::render_frame`) must equal the
//! host's bit for bit; their dB against the f64 pipeline are printed, and
//! the integer one must meet the floor `tests/fixed_view.rs` asserts on the
//! host's (the same bits).
//!
//! Needs the QEMU outputs, so it is ignored in `cargo test` and run by
//! `scripts/firmware.sh` as
//! `FVR_QEMU_OUT=<dir> cargo test -p fvr-firmware --test qemu_fixed -- --ignored`.

mod common;
#[allow(dead_code)]
#[path = "../src/fixed_input.rs"]
mod fixed_input;

use std::path::Path;

use common::fixed::{f64_view, integer_floor_db, integer_view, values};
use common::{count_differing, exact_image, host_image, le_f32s, qemu_out_dir, read_output};
use fixed_input::{f32_from_q15, q15_block, q31_from_q15, LEN, SIDE};
use fvr_core::dht::fixed::{self, FixedSample, FixedTwiddles};
use fvr_core::dht::{self, Twiddles};
use fvr_engine::image::snr_db;
use fvr_firmware::scene::SCENE_FRAMES;

/// The input block, as Q15 mantissas.
fn input() -> Vec<i16> {
    let mut block = vec![0i16; LEN];
    q15_block(&mut block);
    block
}

/// The true inverse 2D DHT of the input's values, in f64.
fn reference(input: &[i16]) -> Vec<f64> {
    let mut data: Vec<f64> = input.iter().map(|&m| m as f64 / 32768.0).collect();
    let mut buf = vec![0.0f64; Twiddles::<f64>::buffer_len(SIDE)];
    let tw = Twiddles::new(&mut buf, SIDE).unwrap();
    let mut column = vec![0.0f64; SIDE];
    dht::idht_2d(&mut data, SIDE, SIDE, &mut column, &tw).unwrap();
    data
}

/// Peak over RMS of the nonzero values.
fn crest(v: &[f64]) -> f64 {
    let nonzero: Vec<f64> = v.iter().copied().filter(|x| *x != 0.0).collect();
    let peak = nonzero.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let rms = (nonzero.iter().map(|x| x * x).sum::<f64>() / nonzero.len() as f64).sqrt();
    peak / rms
}

/// The crest factor the floor uses: the worst of the input, the block after
/// the row pass (1D transforms of the rows, in f64), the output, and the
/// Gaussian bound `√(2·ln N) + 1` of random data over `N` values.
fn worst_crest(input: &[i16], output: &[f64]) -> f64 {
    let values: Vec<f64> = input.iter().map(|&m| m as f64).collect();
    let rows: Vec<f64> = values
        .chunks_exact(SIDE)
        .flat_map(|row| {
            (0..SIDE).map(move |k| {
                row.iter()
                    .enumerate()
                    .map(|(x, v)| {
                        let a = 2.0 * std::f64::consts::PI * (k * x % SIDE) as f64 / SIDE as f64;
                        v * (a.cos() + a.sin())
                    })
                    .sum::<f64>()
            })
        })
        .collect();
    let gaussian = (2.0 * (LEN as f64).ln()).sqrt() + 1.0;
    [crest(&values), crest(&rows), crest(output), gaussian]
        .into_iter()
        .fold(0.0, f64::max)
}

/// The model's floor for `frac` fraction bits over a 2D block (`2·log₂n`
/// stages and the Hao–Bracewell correction).
fn floor_db(frac: u32, crest: f64) -> f64 {
    let roundings = 2.0 * SIDE.trailing_zeros() as f64 + 1.0;
    6.0206 * (frac as f64 - 3.0) + 10.0 * 6f64.log10()
        - 10.0 * roundings.log10()
        - 20.0 * crest.log10()
}

/// The QEMU result `[exponent i32][mantissas]` of `name`, against the host's
/// `fixed::idht_2d` of `block`: bit-identical, and its SNR against
/// `reference` at least the model's floor.
fn check_fixed<S: FixedSample>(
    dir: &Path,
    name: &str,
    mut block: Vec<S>,
    from_le: fn(&[u8]) -> S,
    reference: &[f64],
    crest: f64,
) -> Result<(), String> {
    let mut buf = vec![S::default(); FixedTwiddles::<S>::buffer_len(SIDE)];
    let tw = FixedTwiddles::new(&mut buf, SIDE).unwrap();
    let exp = fixed::idht_2d(&mut block, SIDE, SIDE, &tw).unwrap();
    let bytes = read_output(dir, name);
    let width = std::mem::size_of::<S>();
    assert_eq!(bytes.len(), 4 + width * LEN, "{name}");
    let device_exp = i32::from_le_bytes(bytes[..4].try_into().unwrap());
    let device: Vec<S> = bytes[4..].chunks_exact(width).map(from_le).collect();
    let differing = block.iter().zip(&device).filter(|(a, b)| a != b).count();
    let scale = exp as f64 - S::FRAC_BITS as f64;
    let values: Vec<f64> = device
        .iter()
        .map(|m| m.to_i64() as f64 * scale.exp2())
        .collect();
    let snr = snr_db(reference, &values);
    let floor = floor_db(S::FRAC_BITS, crest);
    println!(
        "{name}: exponent {device_exp} (host {exp}), {differing} of {LEN} mantissas differ from the \
         host; {snr:.1} dB against f64 (floor {floor:.1} dB, crest factor {crest:.2})"
    );
    if differing != 0 || device_exp != exp {
        return Err(format!("{name}: not bit-identical to the host"));
    }
    if snr < floor {
        return Err(format!(
            "{name}: {snr:.1} dB is below the floor {floor:.1} dB"
        ));
    }
    Ok(())
}

#[test]
#[ignore = "needs the firmware's QEMU outputs: bash scripts/firmware.sh"]
fn qemu_fixed_transforms_equal_host_bit_for_bit() {
    let dir = qemu_out_dir();
    let input = input();
    let reference = reference(&input);
    let crest = worst_crest(&input, &reference);
    let mut failures = Vec::new();

    let q15 = check_fixed(
        &dir,
        "fvr-fixed-bench-q15.bin",
        input.clone(),
        |b| i16::from_le_bytes([b[0], b[1]]),
        &reference,
        crest,
    );
    let q31 = check_fixed(
        &dir,
        "fvr-fixed-bench-q31.bin",
        input.iter().map(|&m| q31_from_q15(m)).collect(),
        |b| i32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        &reference,
        crest,
    );
    failures.extend(q15.err());
    failures.extend(q31.err());

    let mut host: Vec<f32> = input.iter().map(|&m| f32_from_q15(m)).collect();
    let mut buf = vec![0.0f32; Twiddles::<f32>::buffer_len(SIDE)];
    let tw = Twiddles::new(&mut buf, SIDE).unwrap();
    let mut column = vec![0.0f32; SIDE];
    dht::idht_2d(&mut host, SIDE, SIDE, &mut column, &tw).unwrap();
    let bytes = read_output(&dir, "fvr-fixed-bench-f32.bin");
    assert_eq!(bytes.len(), 4 * LEN);
    let device = le_f32s(&bytes);
    let differing = count_differing(&host, &device, f32::to_bits);
    let values: Vec<f64> = device.iter().map(|&v| v as f64).collect();
    println!(
        "fvr-fixed-bench-f32.bin: {differing} of {LEN} values differ from the host; \
         {:.1} dB against f64 (soft float)",
        snr_db(&reference, &values)
    );
    if differing != 0 {
        failures.push("f32: not bit-identical to the host".to_string());
    }
    failures.extend(check_views(&dir).err());
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The two whole views against the host's, bit for bit, and their dB.
fn check_views(dir: &Path) -> Result<(), String> {
    let (f64_image, f64_slice) = f64_view();
    let exact = exact_image(&SCENE_FRAMES[0]);

    let (exp, host) = integer_view();
    let bytes = read_output(dir, "fvr-fixed-bench-view-q15.bin");
    assert_eq!(bytes.len(), 4 + 2 * host.len(), "view-q15");
    let device_exp = i32::from_le_bytes(bytes[..4].try_into().unwrap());
    let device: Vec<i16> = bytes[4..]
        .chunks_exact(2)
        .map(|b| i16::from_le_bytes([b[0], b[1]]))
        .collect();
    let differing = host.iter().zip(&device).filter(|(a, b)| a != b).count();
    let image = values(device_exp, &device);
    let (against_f64, floor) = (
        snr_db(&f64_image, &image),
        integer_floor_db(&f64_slice, &f64_image),
    );
    println!(
        "fvr-fixed-bench-view-q15.bin: exponent {device_exp} (host {exp}), {differing} of {} \
         pixels differ from the host; {against_f64:.1} dB against the f64 pipeline (floor \
         {floor:.1} dB), {:.1} dB against exact line integrals",
        host.len(),
        snr_db(&exact, &image)
    );

    let host32 = host_image(&SCENE_FRAMES[0]);
    let bytes = read_output(dir, "fvr-fixed-bench-view-f32.bin");
    assert_eq!(bytes.len(), 4 * host32.len(), "view-f32");
    let device32 = le_f32s(&bytes);
    let differing32 = count_differing(&host32, &device32, f32::to_bits);
    let image32: Vec<f64> = device32.iter().map(|&v| v as f64).collect();
    println!(
        "fvr-fixed-bench-view-f32.bin: {differing32} of {} pixels differ from the host; \
         {:.1} dB against the f64 pipeline, {:.1} dB against exact line integrals (soft float, \
         f16 spectrum)",
        host32.len(),
        snr_db(&f64_image, &image32),
        snr_db(&exact, &image32)
    );
    if differing != 0 || device_exp != exp {
        return Err("view-q15: not bit-identical to the host".to_string());
    }
    if differing32 != 0 {
        return Err("view-f32: not bit-identical to the host".to_string());
    }
    if against_f64 < floor {
        return Err(format!(
            "view-q15: {against_f64:.1} dB is below the floor {floor:.1} dB"
        ));
    }
    Ok(())
}
