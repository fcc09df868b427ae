//! `fvr turntable` takes every option of `fvr render` that shapes a view:
//! depth cue, ambient, lights (flags or a scene's `[[lights]]`), resample
//! and preview level; a lit turntable is an RGB APNG whose frames are the
//! renders of their views.

mod common;
use common::{assert_error, assert_ok, fvr_line, fvr_ok, png_frames, temp_dir};
use std::path::Path;

/// Every frame of a PNG or APNG, decoded: (width, height, colour type,
/// frames of bytes).
fn frames(path: &Path) -> (u32, u32, png::ColorType, Vec<Vec<u8>>) {
    let (info, frames) = png_frames(path);
    (info.width, info.height, info.color_type, frames)
}

/// Pearson correlation of two byte images.
fn correlation(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len());
    let n = a.len() as f64;
    let mean = |v: &[u8]| v.iter().map(|&x| x as f64).sum::<f64>() / n;
    let (ma, mb) = (mean(a), mean(b));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (&x, &y) in a.iter().zip(b) {
        let (x, y) = (x as f64 - ma, y as f64 - mb);
        sab += x * y;
        saa += x * x;
        sbb += y * y;
    }
    sab / (saa * sbb).sqrt()
}

/// The three-light teapot animates in colour, and its first frame is
/// `fvr render` of the first view. A one-frame turntable has the render's
/// window (percentiles of that one view), so its frame is the render's PNG
/// byte for byte; in a 12-frame turn the window spans all frames, so frame
/// 0 is the same image under another linear window (correlation ≈ 1).
#[test]
fn the_three_light_teapot_turns_in_colour_and_frame_0_is_its_render() {
    let dir = temp_dir("turntable-teapot");
    let out = fvr_ok(
        "turntable teapot@32 --light-ring 3 --frames 12 --out t.apng --quiet",
        &dir,
    );
    assert!(out.contains("12 frames, 32x32 RGB"), "{out}");
    let (w, h, color, turn) = frames(&dir.join("t.apng"));
    assert_eq!((w, h, color, turn.len()), (32, 32, png::ColorType::Rgb, 12));
    // Coloured: some pixel's channels differ.
    assert!(turn[0].chunks(3).any(|p| p[0] != p[1] || p[1] != p[2]));
    // The camera moves: frames differ.
    assert_ne!(turn[0], turn[3]);

    fvr_ok(
        "render teapot@32 --light-ring 3 --dir 0,-1,0 --up 0,0,1 --out f.png --quiet",
        &dir,
    );
    let (_, _, color, render) = frames(&dir.join("f.png"));
    assert_eq!(color, png::ColorType::Rgb);
    let r = correlation(&turn[0], &render[0]);
    assert!(r > 0.99, "frame 0 against the render: correlation {r}");

    fvr_ok(
        "turntable teapot@32 --light-ring 3 --frames 1 --out one.apng --quiet",
        &dir,
    );
    let (_, _, _, one) = frames(&dir.join("one.apng"));
    assert!(
        one[0] == render[0],
        "the one-frame turntable differs from the render"
    );
}

/// A scene's `[[lights]]` and `[shading]` make a shaded turntable, not an
/// X-ray one.
#[test]
fn a_scene_with_lights_makes_a_shaded_turntable() {
    let dir = temp_dir("turntable-scene");
    std::fs::write(
        dir.join("lit.toml"),
        "[volume]\nbuiltin = \"teapot@32\"\n\
         [shading]\nambient = 0.1\n\
         [[lights]]\ndirection = [0, -1, 1]\ncolor = [1, 0.2, 0.2]\n\
         [turntable]\nframes = 3\npath = \"lit.apng\"\n",
    )
    .unwrap();
    let out = fvr_line("turntable --scene lit.toml --quiet", &dir);
    let text = assert_ok(&out);
    assert!(text.contains("3 frames, 32x32 RGB"), "{text}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("does not use"), "{err}");
    let (_, _, color, turn) = frames(&dir.join("lit.apng"));
    assert_eq!((color, turn.len()), (png::ColorType::Rgb, 3));
}

/// Cue, ambient, resample and preview level are accepted; a preview level
/// shrinks the frames; combinations the engine cannot render are refused in
/// one line before anything is written.
#[test]
fn turntable_takes_the_render_options_and_refuses_what_cannot_be_done() {
    let dir = temp_dir("turntable-options");
    let text = fvr_ok(
        "turntable gaussians@32 --frames 2 --depth-cue linear:1,0.3 --ambient 0.5 \
         --resample 24 --out cue.apng --stats-json",
        &dir,
    );
    let stats: serde_json::Value = serde_json::from_str(text.trim()).unwrap();
    assert_eq!(stats["dims"], serde_json::json!([24, 24, 24]), "{stats}");
    assert_eq!(stats["frames"], 2, "{stats}");
    let text = fvr_ok(
        "turntable gaussians@32 --frames 2 --preview-level 1 --out p.apng --quiet",
        &dir,
    );
    assert!(text.contains("2 frames, 16x16 grey"), "{text}");
    let (w, _, _, _) = frames(&dir.join("p.apng"));
    assert_eq!(w, 16);
    for (line, needle) in [
        (
            "turntable teapot@32 --frames 2 --light-ring 3 --preview-level 1 --out bad.apng",
            "plain X-ray",
        ),
        (
            "turntable teapot@32 --frames 2 --light-ring 3 --colormap hot --out bad.apng",
            "--colormap",
        ),
        (
            "turntable teapot@32 --frames 2 --light 0,0,0:1 --out bad.apng",
            "zero direction",
        ),
    ] {
        let out = fvr_line(line, &dir);
        assert_error(&out, &["fvr: error:", needle]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(!dir.join("bad.apng").exists(), "{line}");
    }
}

/// `--zoom F` magnifies every frame as it magnifies a render: a one-frame
/// zoomed turntable is the zoomed render's PNG, pixel for pixel, and a
/// longer turn has frames F times as wide. Lights, depth cues and previews
/// are refused with it, before any work.
#[test]
fn zoomed_turntable_frames_are_zoomed_renders() {
    let dir = temp_dir("turntable-zoom");
    fvr_ok(
        "render sphere@24 --dir 0,-1,0 --zoom 2 --out r.png --quiet",
        &dir,
    );
    fvr_ok(
        "turntable sphere@24 --frames 1 --zoom 2 --out one.apng --quiet",
        &dir,
    );
    let (w, rendered) = common::grey_png(&dir.join("r.png"));
    let (tw, th, _, one) = frames(&dir.join("one.apng"));
    assert_eq!((tw as usize, th as usize), (w, w));
    assert_eq!(one[0], rendered, "frame 0 is the zoomed render");
    let stdout = fvr_ok(
        "turntable sphere@24 --frames 3 --zoom 3 --out three.apng --stats-json",
        &dir,
    );
    let stats: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    let (tw, _, _, turn) = frames(&dir.join("three.apng"));
    assert_eq!(turn.len(), 3);
    assert_eq!(tw as usize, 3 * w / 2, "{stats}");
    assert_eq!(stats["image"][0], 3 * w / 2, "{stats}");
    for line in [
        "turntable sphere@24 --frames 2 --zoom 2 --light-ring 3 --out bad.apng",
        "turntable sphere@24 --frames 2 --zoom 2 --depth-cue linear:1,0.2 --out bad.apng",
        "turntable sphere@24 --frames 2 --zoom 2 --preview-level 1 --out bad.apng",
    ] {
        let out = fvr_line(line, &dir);
        assert_error(&out, &["--zoom 2 magnifies plain X-ray turntables"]);
        assert!(!dir.join("bad.apng").exists(), "{line}");
    }
}
