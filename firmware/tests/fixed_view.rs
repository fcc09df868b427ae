//! The Cortex-M3's integer view (`fvr_firmware::fixed_view`) on the host
//! against the f64 pipeline and exact line integrals.

mod common;

use common::fixed::{f64_view, integer_floor_db, integer_view, values};
use common::{exact_image, floor_db, host_image};
use fvr_engine::image::snr_db;
use fvr_firmware::scene::SCENE_FRAMES;

/// Against the f64 pipeline: at least the floor of the Q15 error model
/// (`common::fixed::integer_floor_db`) and the 45 dB the integer view is
/// required to reach. Against exact line integrals: the README's kb3 floor
/// that the M4F's f32 frames meet (`common::floor_db`).
#[test]
fn integer_view_meets_the_q15_floor_against_f64() {
    let (exponent, mantissas) = integer_view();
    let integer = values(exponent, &mantissas);
    let (f64_image, f64_slice) = f64_view();
    let plain = &SCENE_FRAMES[0];
    let exact = exact_image(plain);
    let f32_image: Vec<f64> = host_image(plain).iter().map(|&v| v as f64).collect();
    let floor = integer_floor_db(&f64_slice, &f64_image);
    let (against_f64, against_exact) = (snr_db(&f64_image, &integer), snr_db(&exact, &integer));
    println!(
        "integer view: {against_f64:.1} dB against the f64 pipeline (floor {floor:.1} dB), \
         {against_exact:.1} dB against exact line integrals; f32 from f16: {:.1} and {:.1} dB; \
         f64 pipeline against exact: {:.1} dB",
        snr_db(&f64_image, &f32_image),
        snr_db(&exact, &f32_image),
        snr_db(&exact, &f64_image),
    );
    assert!(
        against_f64 >= floor,
        "{against_f64:.1} dB below the model's {floor:.1} dB"
    );
    assert!(against_f64 >= 45.0, "{against_f64:.1} dB below 45 dB");
    let readme = floor_db(plain);
    assert!(
        against_exact >= readme,
        "{against_exact:.1} dB against exact line integrals, below {readme:.1} dB"
    );
}
