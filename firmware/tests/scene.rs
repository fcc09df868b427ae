//! The firmware's scene, rendered on the host from the same flash tables:
//! the tables are right (the image matches exact line integrals), and the
//! staged render the firmware times is the whole of `render`.

mod common;

use common::{exact_image, floor_db, host_image, snr_db, stored_for};
use fvr_core::dht::Twiddles;
use fvr_core::f16;
use fvr_core::filter::{Filter, KernelTable};
use fvr_core::spectrum::{DenseVolume, Spectrum};
use fvr_firmware::frame::{
    render_frame, FrameBuffers, FrameError, InstructionClock, AUX_LEN, GRID_LEN, IMAGE_LEN,
};
use fvr_firmware::scene::{density, DIMS, OVERSAMPLE, PROGRAMS};
use fvr_firmware::stored::{all, twiddles};
use std::cell::Cell;

/// A clock that advances by one per reading, so counts are positive and
/// ordered.
struct Ticks(Cell<u64>);

impl InstructionClock for Ticks {
    fn now(&self) -> u64 {
        self.0.set(self.0.get() + 1);
        self.0.get()
    }
}

#[test]
fn every_frame_matches_exact_line_integrals_within_the_readme_floor() {
    for (program, frames) in PROGRAMS {
        for spec in frames {
            let img = host_image(spec);
            let snr = snr_db(&exact_image(spec), &img);
            println!(
                "{program} {}: {snr:.1} dB against exact line integrals",
                spec.name
            );
            assert!(
                snr >= floor_db(spec.filter),
                "{program} {}: {snr:.1} dB < {} dB",
                spec.name,
                floor_db(spec.filter)
            );
        }
    }
}

#[test]
fn staged_render_equals_render_bit_for_bit() {
    let tw = twiddles().unwrap();
    let (mut grid, mut aux) = (vec![0.0; GRID_LEN], vec![0.0; AUX_LEN]);
    let (mut image, mut staged) = (vec![0.0; IMAGE_LEN], vec![0.0; IMAGE_LEN]);
    for (_, frames) in PROGRAMS {
        for spec in frames {
            let mut bufs = FrameBuffers {
                grid: &mut grid,
                aux: &mut aux,
                image: &mut image,
                staged: &mut staged,
            };
            let counts =
                render_frame(spec, stored_for(spec), &tw, &mut bufs, &Ticks(Cell::new(0))).unwrap();
            assert_eq!(
                (counts.render, counts.extract, counts.inverse, counts.dht_2d),
                (1, 1, 1, 1)
            );
            let host = host_image(spec);
            assert!(image
                .iter()
                .zip(&host)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }
}

#[test]
fn a_frame_without_its_spectrum_is_an_error_naming_it() {
    let spec = &fvr_firmware::scene::BENCH_FRAMES[2];
    let err =
        fvr_firmware::frame::spectrum_for(spec, &[&fvr_firmware::stored::DENSITY_KB3]).unwrap_err();
    assert_eq!(err, FrameError::MissingSpectrum { frame: "plain-kb6" });
    assert_eq!(
        err.to_string(),
        "frame plain-kb6: no stored spectrum for its filter"
    );
}

/// The flash tables are what the core makes from the phantom now (so the
/// build script and the library agree, and nothing stale is linked).
#[test]
fn flash_tables_equal_a_fresh_preparation() {
    let [nx, ny, nz] = DIMS;
    let mut voxels = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                voxels.push(density([i as f64, j as f64, k as f64]) as f32);
            }
        }
    }
    let volume = DenseVolume::new(DIMS, &voxels).unwrap();
    let n = nx;
    let mut tw_buf = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
    Twiddles::new(&mut tw_buf, n).unwrap();
    assert_eq!(tw_buf.as_slice(), &fvr_firmware::stored::TWIDDLES[..]);
    let tw = Twiddles::from_table(&tw_buf, n).unwrap();
    let mut scratch = vec![0.0f32; fvr_core::spectrum::prepare_scratch_len(n)];
    for stored in all() {
        let (filter, _) = Filter::fit(stored.filter_kind(), OVERSAMPLE, &volume).unwrap();
        assert_eq!(stored.filter().unwrap(), filter);
        let mut data = vec![f16::ZERO; n * n * n];
        let spec = Spectrum::prepare(&volume, filter, &mut data, &mut scratch, &tw).unwrap();
        assert_eq!(spec.scale(), stored.scale);
        assert!(data
            .iter()
            .zip(stored.data)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
        let kernel = KernelTable::<f32>::new(filter);
        assert_eq!(kernel.values(), stored.kernel);
        assert_eq!(
            stored.flash_bytes(),
            2 * n * n * n + 4 * kernel.values().len()
        );
    }
}
