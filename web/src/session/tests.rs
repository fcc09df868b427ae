use super::*;
use fvr_engine::volume::phantom::{sample, GaussianMixture};

fn phantom() -> Volume {
    sample(&GaussianMixture::random(7, 32, 6), [32; 3])
}

const PLAIN: Options = Options {
    accuracy_db: 40.0,
    cue: Cue::None,
    lights: false,
};

/// A session holding [`phantom`], prepared with `options`.
fn session(options: Options) -> Session {
    let mut s = Session::new();
    s.set_volume(phantom());
    s.prepare(options).unwrap();
    s
}

fn ask(level: u32, zoom: f64) -> Ask {
    Ask {
        view: View::along([0.3, 1.0, -0.45]),
        zoom,
        level,
    }
}

#[test]
fn full_views_are_the_renderers_own() {
    let s = session(PLAIN);
    let image = s.render(&ask(0, 1.0)).unwrap();
    let settings = Settings {
        accuracy_db: Some(40.0),
        ..Settings::default()
    };
    let direct = Renderer::new(&phantom(), settings).unwrap();
    let (want, _) = direct.render(&ask(0, 1.0).view, None).unwrap();
    assert_eq!(image, want);
    assert!(image.data.iter().any(|&v| v > 0.0));
}

#[test]
fn previews_shrink_and_zoom_magnifies() {
    let s = session(PLAIN);
    let full = s.render(&ask(0, 1.0)).unwrap();
    let preview = s.render(&ask(1, 1.0)).unwrap();
    assert_eq!(
        (preview.width, preview.height),
        (full.width / 2, full.height / 2)
    );
    // Zoom 2 halves the pixel size: the image's sum (the integral over the
    // image's area) shrinks where the volume overflows the smaller field,
    // and the centre pixel, a line integral, stays close.
    let zoomed = s.render(&ask(0, 2.0)).unwrap();
    assert_eq!((zoomed.width, zoomed.height), (full.width, full.height));
    let centre = |i: &Image| i.data[(i.height / 2) * i.width + i.width / 2];
    let (a, b) = (centre(&full), centre(&zoomed));
    assert!((a - b).abs() <= 0.05 * a.abs().max(1e-9), "{a} vs {b}");
    assert_ne!(full.data, zoomed.data);
}

#[test]
fn lights_give_colour_and_cues_change_the_image() {
    let mut s = session(Options {
        lights: true,
        ..PLAIN
    });
    let lit = s.render(&ask(0, 1.0)).unwrap();
    assert_eq!(lit.channels, 3);
    s.prepare(Options {
        cue: Cue::Sine,
        ..PLAIN
    })
    .unwrap();
    let cued = s.render(&ask(0, 1.0)).unwrap();
    s.prepare(PLAIN).unwrap();
    let plain = s.render(&ask(0, 1.0)).unwrap();
    assert_eq!(cued.channels, 1);
    assert_ne!(cued.data, plain.data);
}

#[test]
fn bad_requests_are_one_line_errors() {
    let mut s = Session::new();
    assert!(s.prepare(PLAIN).unwrap_err().contains("no volume"));
    assert!(s.render(&ask(0, 1.0)).unwrap_err().contains("prepared"));
    s.set_volume(phantom());
    let e = s
        .prepare(Options {
            accuracy_db: f64::NAN,
            ..PLAIN
        })
        .unwrap_err();
    assert!(e.contains("accuracy target"), "{e}");
    s.prepare(PLAIN).unwrap();
    assert!(s.render(&ask(0, 0.0)).unwrap_err().contains("zoom"));
    let mut zero = ask(0, 1.0);
    zero.view.dir = [0.0; 3];
    assert!(!s.render(&zero).unwrap_err().contains('\n'));
}
