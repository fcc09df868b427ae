//! Host-side helpers shared by the firmware's integration tests.
#![allow(dead_code)] // each test binary uses a different part

pub mod fixed;

use std::path::{Path, PathBuf};

use fvr_core::geometry::{center, Frame};
use fvr_core::image::{aux_len, grid_len};
use fvr_core::render::{render, Buffers, Request, Source};
use fvr_core::shading::fields_len;
use fvr_engine::volume::phantom::{Gaussian, GaussianMixture, Phantom};
use fvr_firmware::frame::{tables_for, FrameTables, InstructionClock};
use fvr_firmware::scene::{density, Blob, FrameSpec, Shading, BLOBS, DIMS, IMAGE_SIDE};
use fvr_firmware::stored::{all, all_derivatives, twiddles};
use fvr_host::reference::shaded::exact_scene_projection;

/// Simpson step (voxels) of the exact references' numerically integrated
/// `|∇f|` term, as in tests/tests/shading.rs: for Gaussians of σ ≥ 1.8
/// voxels its fourth-order error is far below every figure measured here.
pub const GRADIENT_STEP: f64 = 0.05;

/// The phantom sampled at voxel centres `(i, j, k)`, `i` fastest, rounded
/// to f32: as `build.rs` samples it for the flash tables.
pub fn phantom_voxels() -> Vec<f32> {
    let [nx, ny, nz] = DIMS;
    let mut voxels = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                voxels.push(density([i as f64, j as f64, k as f64]) as f32);
            }
        }
    }
    voxels
}

/// The flash tables a frame reads, among all the stored ones.
pub fn tables(spec: &FrameSpec) -> FrameTables {
    tables_for(spec, &all(), &all_derivatives()).expect("every stored table is in all()")
}

/// The host core's image of a frame, `channels·IMAGE_SIDE²` values
/// (channel fastest): `fvr_core::render::render` or
/// `fvr_core::render::render` with a scene in f32 from the same flash tables
/// the firmware links.
pub fn host_image(spec: &FrameSpec) -> Vec<f32> {
    let t = tables(spec);
    let spectrum = t.density.spectrum().unwrap();
    let kernel = t.density.kernel_table().unwrap();
    let tw = twiddles().unwrap();
    let n = spectrum.n();
    let mut aux = vec![0.0f32; aux_len(n)];
    match spec.shading {
        Shading::Plain => {
            let mut grid = vec![0.0f32; grid_len(n)];
            let mut out = vec![0.0f32; IMAGE_SIDE * IMAGE_SIDE];
            render(
                &Source::new(&spectrum, &kernel, &tw),
                &Request::new(spec.view, IMAGE_SIDE, IMAGE_SIDE),
                Buffers::new(&mut grid, &mut aux, &mut out),
            )
            .unwrap();
            out
        }
        Shading::Scene(s) => {
            let scene = s.scene().unwrap();
            let gradient = t.gradient.map(|g| g.spectrum().unwrap());
            let derivative = t.derivative.map(|d| d.table().unwrap());
            let mut fields = vec![0.0f32; fields_len(&scene, n)];
            let mut out = vec![0.0f32; scene.channels() * IMAGE_SIDE * IMAGE_SIDE];
            let channels = render(
                &Source {
                    spectrum: &spectrum,
                    gradient: gradient.as_ref(),
                    kernel: &kernel,
                    derivative: derivative.as_ref(),
                    twiddles: &tw,
                },
                &Request {
                    scene: Some(&scene),
                    ..Request::new(spec.view, IMAGE_SIDE, IMAGE_SIDE)
                },
                Buffers::new(&mut fields, &mut aux, &mut out),
            )
            .unwrap();
            assert_eq!(channels, s.channels());
            out
        }
    }
}

fn gaussian(b: &Blob) -> Gaussian {
    Gaussian {
        amplitude: b.amplitude,
        center: b.center,
        sigmas: b.sigmas,
        rotation: b.rotation,
    }
}

/// The scene's phantom as the host's analytic mixture.
pub fn mixture() -> GaussianMixture {
    GaussianMixture {
        components: BLOBS.iter().map(gaussian).collect(),
    }
}

/// The f64 reference of a frame: exact line integrals of the phantom
/// through every pixel for a plain frame; for a cued or shaded one,
/// `exact_scene_projection` (closed forms, `|∇f|` by Simpson's rule at
/// [`GRADIENT_STEP`]).
pub fn exact_image(spec: &FrameSpec) -> Vec<f64> {
    let frame: Frame = spec.view.frame().unwrap();
    let mixture = mixture();
    match spec.shading {
        Shading::Plain => {
            let c = center(DIMS);
            let mut out = Vec::with_capacity(IMAGE_SIDE * IMAGE_SIDE);
            for row in 0..IMAGE_SIDE {
                for col in 0..IMAGE_SIDE {
                    let p = frame.pixel_position(c, IMAGE_SIDE, IMAGE_SIDE, col as f64, row as f64);
                    out.push(
                        mixture
                            .components
                            .iter()
                            .map(|g| g.line_integral(p, frame.dir))
                            .sum(),
                    );
                }
            }
            out
        }
        Shading::Scene(s) => {
            let image = exact_scene_projection(
                &mixture,
                DIMS,
                &s.scene().unwrap(),
                &spec.view,
                (IMAGE_SIDE, IMAGE_SIDE),
                GRADIENT_STEP,
            )
            .unwrap();
            assert_eq!(image.channels, s.channels());
            image.data
        }
    }
}

/// SNR in dB of `img` against `reference`: 10·log10(Σref² / Σ(img − ref)²).
pub fn snr_db(reference: &[f64], img: &[f32]) -> f64 {
    let (mut s, mut e) = (0.0, 0.0);
    for (r, v) in reference.iter().zip(img) {
        s += r * r;
        e += (*v as f64 - r) * (*v as f64 - r);
    }
    10.0 * (s / e).log10()
}

/// The README's accuracy floor for a frame against its f64 reference
/// ([`exact_image`]), for a filter at oversampling 1 with f16 storage:
/// tests/tests/projection.rs for plain frames. Cued and shaded frames use
/// the same kb3 floor (see tests/scene.rs for why it holds).
pub fn floor_db(spec: &FrameSpec) -> f64 {
    use fvr_core::filter::FilterKind::*;
    match spec.filter {
        Kb3 => 40.0,
        Kb4 => 50.0,
        Kb6 => 65.0,
        _ => unreachable!("the scene stores Kaiser–Bessel spectra only"),
    }
}

/// A clock for running the device code on the host, where nothing is
/// counted.
pub struct NoClock;

impl InstructionClock for NoClock {
    fn now(&self) -> u64 {
        0
    }
}

/// Prints each `(name, dB, floor)` figure of `what` and returns one line for
/// each below its floor (or NaN).
pub fn below_floors(what: &str, figures: &[(&str, f64, f64)]) -> Vec<String> {
    let mut failures = Vec::new();
    for &(name, db, floor) in figures {
        println!("{what}: {name} {db:.1} dB (floor {floor:.1})");
        if db.is_nan() || db < floor {
            failures.push(format!("{what}: {name} {db:.1} dB < {floor:.1}"));
        }
    }
    failures
}

/// The file `name` QEMU wrote into `dir`.
pub fn read_output(dir: &Path, name: &str) -> Vec<u8> {
    let path = dir.join(name);
    std::fs::read(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (did the firmware run?)", path.display()))
}

/// Little-endian `f32` values.
pub fn le_f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// How many values of `a` and `b` differ in their bits (`bits`, e.g.
/// `f32::to_bits`).
pub fn count_differing<T: Copy, B: PartialEq>(a: &[T], b: &[T], bits: impl Fn(T) -> B) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| bits(**x) != bits(**y))
        .count()
}

/// The directory QEMU wrote the firmware's files to (`FVR_QEMU_OUT`, set by
/// `scripts/firmware.sh`).
pub fn qemu_out_dir() -> PathBuf {
    PathBuf::from(
        std::env::var_os("FVR_QEMU_OUT")
            .expect("FVR_QEMU_OUT must name the directory QEMU wrote the firmware's files to"),
    )
}
