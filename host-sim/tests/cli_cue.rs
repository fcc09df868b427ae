//! Depth cueing stays visible in a PNG: without --window/--level a cued
//! view takes the window of its uncued view (times the cue's largest
//! weight), so near content is brighter than far content and the image
//! differs from the X-ray one; an explicit window applies as given.

mod common;
use common::{fvr_ok, grey_png as grey, temp_dir};

fn mean_abs_diff(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(&x, &y)| (x as f64 - y as f64).abs())
        .sum::<f64>()
        / a.len() as f64
}

/// On the 32³ sphere seen along y, `linear:1,0.3` changes the PNG by more
/// than 5% of 255 on average (17 of 255 measured; 0.01 of 255 when each
/// image took its own percentile window).
#[test]
fn a_cued_render_differs_visibly_from_the_xray_render() {
    let dir = temp_dir("cue-visible");
    fvr_ok("render sphere@32 --dir 0,1,0 --out plain.png --quiet", &dir);
    let out = fvr_ok(
        "render sphere@32 --dir 0,1,0 --depth-cue linear:1,0.3 --out cued.png --stats-json",
        &dir,
    );
    let stats: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(stats["cue_window"], true, "{stats}");
    let (_, plain) = grey(&dir.join("plain.png"));
    let (_, cued) = grey(&dir.join("cued.png"));
    let d = mean_abs_diff(&plain, &cued);
    assert!(d > 0.05 * 255.0, "mean absolute difference {d:.2} of 255");
}

/// Two equal cubes side by side, one near the eye and one far: the cued
/// render shows the near one brighter (the X-ray render shows them alike).
#[test]
fn near_content_is_brighter_than_far_content() {
    let dir = temp_dir("cue-near");
    let n = 32;
    let mut v = vec![0u8; n * n * n];
    for z in 12..20 {
        for y in 0..n {
            for x in 0..n {
                let near = (4..10).contains(&x) && (4..10).contains(&y);
                let far = (22..28).contains(&x) && (22..28).contains(&y);
                if near || far {
                    v[x + n * (y + n * z)] = 200;
                }
            }
        }
    }
    std::fs::write(dir.join("cubes.raw"), &v).unwrap();
    // Along +y: x runs left to right, the near cube (small y) on the left.
    let halves = |name: &str| {
        let (w, px) = grey(&dir.join(name));
        let (mut left, mut right) = (0u8, 0u8);
        for (i, &p) in px.iter().enumerate() {
            if i % w < w / 2 {
                left = left.max(p);
            } else {
                right = right.max(p);
            }
        }
        (left as f64, right as f64)
    };
    let render = "render cubes.raw --raw-dims 32,32,32 --dir 0,1,0 --quiet";
    fvr_ok(&format!("{render} --out plain.png"), &dir);
    let (l, r) = halves("plain.png");
    assert!((l - r).abs() <= 2.0, "X-ray: near {l}, far {r}");
    fvr_ok(
        &format!("{render} --depth-cue linear:1,0.3 --out cued.png"),
        &dir,
    );
    let (near, far) = halves("cued.png");
    assert!(near > 1.5 * far && far > 0.0, "near {near}, far {far}");
    // The near cube is dimmed by its weight (about 0.8), not stretched back
    // to white as the cued image's own window would.
    assert!(near < 250.0, "near {near}");
}

/// --window/--level apply to a cued render as given.
#[test]
fn an_explicit_window_is_untouched() {
    let dir = temp_dir("cue-window");
    let base = "render sphere@32 --dir 0,1,0 --depth-cue linear:1,0.3 --quiet";
    fvr_ok(&format!("{base} --window 40 --level 20 --out w.png"), &dir);
    fvr_ok(&format!("{base} --out w.nrrd"), &dir);
    let bytes = std::fs::read(dir.join("w.nrrd")).unwrap();
    let end = bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    let values: Vec<f32> = bytes[end..]
        .chunks(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let (_, png) = grey(&dir.join("w.png"));
    assert_eq!(values.len(), png.len());
    for (&v, &p) in values.iter().zip(&png) {
        let want = ((v as f64 / 40.0).clamp(0.0, 1.0) * 255.0).round();
        assert!((want - p as f64).abs() <= 1.0, "{v} -> {p}, want {want}");
    }
}

/// A turntable windows a cued view as a render does: a one-frame cued
/// turntable is the cued render's PNG byte for byte.
#[test]
fn a_cued_turntable_takes_the_cue_aware_window() {
    let dir = temp_dir("cue-turntable");
    fvr_ok(
        "render sphere@32 --dir 0,-1,0 --depth-cue linear:1,0.3 --out r.png --quiet",
        &dir,
    );
    fvr_ok(
        "turntable sphere@32 --frames 1 --depth-cue linear:1,0.3 --out t.apng --quiet",
        &dir,
    );
    let (_, render) = grey(&dir.join("r.png"));
    let (_, frame) = grey(&dir.join("t.apng"));
    assert!(
        render == frame,
        "the cued turntable's frame differs from the render"
    );
}
