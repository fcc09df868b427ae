//! `fvr render --zoom F`: the same field of view, `F` times as many pixels
//! per side, against the exact line integrals; the flag on the command
//! line.

mod common;
use common::{assert_error, assert_ok, fvr_line, fvr_ok, temp_dir};

use fvr_core::geometry::View;
use fvr_engine::{Renderer, Settings};
use fvr_host::reference::{exact_projection_sampled, snr_db};
use fvr_host::sources::phantom_by_name;

/// The plain image of `plain` (`w × h`) repeated `zoom × zoom` times per
/// pixel: what magnifying without interpolation would show.
fn replicated(plain: &[f64], w: usize, h: usize, zoom: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(w * h * zoom * zoom);
    for r in 0..h * zoom {
        for c in 0..w * zoom {
            out.push(plain[(r / zoom) * w + c / zoom]);
        }
    }
    out
}

/// `sphere@32`, a uniform ball with a hard edge, seen obliquely and along
/// an axis: the zoomed image against the ball's exact line integrals at
/// the zoomed pixels. The band-limited interpolant rings at the edge
/// (Gibbs), which costs the plain image its 29 dB and the samples between
/// its pixels about 2.5 dB more; zooming by repeating pixels instead loses
/// far more. Measured (default settings, kb4-class plan): zoom 2 and 4
/// reach 25.7 to 27.2 dB (plain 28.6 to 29.1 dB, repeated pixels 17.1 to
/// 19.1 dB); the test asks for 25 dB, within 3.5 dB of the plain image and
/// 6 dB above repeated pixels.
#[test]
fn zoomed_sphere_against_its_exact_line_integrals() {
    let ph = phantom_by_name("sphere@32").unwrap().unwrap();
    let renderer = Renderer::new(&ph.volume, Settings::default()).unwrap();
    for view in [View::along([1.0, 0.3, 0.2]), View::along([0.0, 1.0, 0.0])] {
        let (plain, _) = renderer.render(&view, None).unwrap();
        let (w, h) = (plain.width, plain.height);
        let exact_at = |zoom: usize| {
            let s = renderer.zoomed_sampling(zoom).unwrap();
            exact_projection_sampled(
                ph.phantom.as_ref(),
                ph.volume.dims,
                &view,
                &s,
                w * zoom,
                h * zoom,
            )
            .unwrap()
        };
        let plain_db = snr_db(&exact_at(1), &plain.data);
        for zoom in [2, 4] {
            let (zoomed, _) = renderer.render_zoomed(&view, None, zoom).unwrap();
            let exact = exact_at(zoom);
            let db = snr_db(&exact, &zoomed.data);
            let blocky = snr_db(&exact, &replicated(&plain.data, w, h, zoom));
            println!(
                "view {:?} zoom {zoom}: {db:.2} dB (plain {plain_db:.2} dB, repeated pixels {blocky:.2} dB)",
                view.dir
            );
            assert!(db >= 25.0, "{db}");
            assert!(db >= plain_db - 3.5, "{db} vs {plain_db}");
            assert!(db >= blocky + 6.0, "{db} vs {blocky}");
        }
    }
}

/// `fvr render brainsmall --zoom 4` writes a 512 × 512 image (the 128-pixel
/// field of view); bad factors are one line, exit 2, nothing written.
#[test]
fn zoom_on_the_command_line() {
    let dir = temp_dir("zoom");
    let out = fvr_line("render brainsmall --dir 0,1,0 --zoom 4 --out z.png", &dir);
    let said = assert_ok(&out);
    assert!(said.contains("512x512"), "{said}");
    let png = std::fs::read(dir.join("z.png")).unwrap();
    // IHDR: width and height, big-endian, at bytes 16..24.
    assert_eq!(&png[16..24], &[0, 0, 2, 0, 0, 0, 2, 0]);
    for bad in ["0", "-2", "0.5", "2.5", "7", "65", "1e9", "inf", "nan"] {
        let out = common::fvr(
            &[
                "render",
                "brainsmall",
                "--dir",
                "0,1,0",
                &format!("--zoom={bad}"),
                "--out",
                "bad.png",
            ],
            &dir,
        );
        assert_error(&out, &["fvr: error:", "--zoom"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(!dir.join("bad.png").exists(), "{bad}");
    }
    // Scenes the zoom does not render: refused by name, nothing written.
    let out = fvr_line(
        "render brainsmall --dir 0,1,0 --zoom 2 --preview-level 1 --out bad.png",
        &dir,
    );
    assert_error(&out, &["--zoom", "--preview-level"]);
    assert!(!dir.join("bad.png").exists());
    // A prepared spectrum has no volume: --zoom and --view are refused.
    fvr_ok("prepare sphere@16 --for host --out s.fvrs --quiet", &dir);
    for flag in ["--zoom 2", "--view left"] {
        let dir_flag = if flag.starts_with("--view") {
            ""
        } else {
            "--dir 1,0,0"
        };
        let out = fvr_line(
            &format!("render s.fvrs {dir_flag} {flag} --out bad.png"),
            &dir,
        );
        assert_error(&out, &["fvr: error:", "--zoom and --view need the volume"]);
        assert!(!dir.join("bad.png").exists());
    }
}

/// `--stats-json` reports the zoomed pixel size: the plain one over F.
#[test]
fn stats_report_the_zoomed_pixel_size() {
    let dir = temp_dir("zoom-stats");
    let json = |zoom: &str| -> serde_json::Value {
        let out = fvr_line(
            &format!("render sphere@32 --dir 1,0,0 --zoom {zoom} --stats-json --out s.nrrd"),
            &dir,
        );
        let said = assert_ok(&out);
        let line = said.lines().find(|l| l.starts_with('{')).unwrap();
        serde_json::from_str(line).unwrap()
    };
    let (plain, zoomed) = (json("1"), json("4"));
    let p = plain["pixel_size"].as_f64().unwrap();
    assert_eq!(zoomed["pixel_size"].as_f64().unwrap(), p / 4.0);
    assert_eq!(
        zoomed["image"][0].as_u64().unwrap(),
        4 * plain["image"][0].as_u64().unwrap()
    );
}
