//! Outputs: window/level, 8- and 16-bit PNG, colormaps, APNG turntables.

mod common;

use common::{png_frames, temp_dir};

use fvr_core::filter::{Filter, FilterKind};
use fvr_core::geometry::Sampling;
use fvr_engine::render::turntable::{orbit, render_views};
use fvr_engine::spectrum::{AnySpectrum, Precision};
use fvr_engine::volume::phantom::{sample, GaussianMixture};
use fvr_host::image::output::{
    percentile_range, write_apng, write_png, Bits, Colormap, Style, Window,
};

#[test]
fn sixteen_bit_grey_keeps_65536_levels_through_an_explicit_window() {
    let dir = temp_dir("png16");
    let pixels: Vec<f64> = (0..256).map(|i| i as f64 / 255.0 * 10.0 - 5.0).collect();
    let style = Style {
        bits: Bits::Sixteen,
        window: Window::from_width_level(10.0, 0.0).unwrap(),
        colormap: Colormap::Gray,
    };
    let path = dir.join("g16.png");
    write_png(&path, 16, 16, &pixels, &style).unwrap();
    let (info, frames) = png_frames(&path);
    assert_eq!(
        (info.bit_depth, info.color_type),
        (png::BitDepth::Sixteen, png::ColorType::Grayscale)
    );
    let values: Vec<u16> = frames[0]
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .collect();
    for (i, &v) in values.iter().enumerate() {
        let expected = (i as f64 / 255.0 * 65535.0).round() as u16;
        assert_eq!(v, expected, "pixel {i}");
    }
    // 256 distinct input values stay distinct (8 bits would merge none here,
    // but the 16-bit steps are 257 apart).
    assert!(values.windows(2).all(|w| w[1] - w[0] == 257));
}

#[test]
fn window_level_maps_the_centre_to_mid_grey_and_clamps_outside() {
    let w = Window::from_width_level(2.0, 1.0).unwrap();
    assert_eq!(w, Window::Range(0.0, 2.0));
    let style = Style {
        window: w,
        ..Style::default()
    };
    let bytes = style.encode(&[1.0, -5.0, 10.0, f64::NAN, 0.5], w.resolve(&[]));
    assert_eq!(bytes, vec![128, 0, 255, 0, 64]);
    for (width, level) in [
        (0.0, 1.0),
        (-1.0, 0.0),
        (f64::NAN, 0.0),
        (1.0, f64::INFINITY),
    ] {
        assert!(
            Window::from_width_level(width, level).is_err(),
            "{width} {level}"
        );
    }
    assert!(Window::from_percentiles(50.0, 50.0).is_err());
    assert!(Window::from_percentiles(-1.0, 50.0).is_err());
    assert!(Window::from_percentiles(1.0, 101.0).is_err());
}

#[test]
fn percentile_window_ignores_outliers_and_non_finite_values() {
    let mut pixels: Vec<f64> = (0..1000).map(|i| i as f64).collect();
    pixels.push(1e12);
    pixels.push(f64::NAN);
    let (lo, hi) = percentile_range(&pixels, 0.5, 99.5);
    assert!(
        (4.0..=6.0).contains(&lo) && (993.0..=996.0).contains(&hi),
        "{lo} {hi}"
    );
    assert_eq!(percentile_range(&pixels, 0.0, 100.0), (0.0, 1e12));
    assert_eq!(percentile_range(&[3.0; 10], 0.5, 99.5), (3.0, 4.0));
    assert_eq!(percentile_range(&[f64::NAN], 0.5, 99.5), (0.0, 1.0));
}

#[test]
fn colormaps_run_black_to_white_through_their_breakpoints() {
    for (map, _) in Colormap::ALL {
        assert_eq!(map.rgb(1.0), [1.0, 1.0, 1.0], "{map:?}");
        assert_eq!(map.rgb(2.0), map.rgb(1.0), "clamped");
        assert_eq!(map.rgb(f64::NAN), map.rgb(0.0));
        // Brightness (sum of channels) never decreases: dense is brighter.
        let sums: Vec<f64> = (0..=100)
            .map(|i| map.rgb(i as f64 / 100.0).iter().sum())
            .collect();
        assert!(sums.windows(2).all(|w| w[1] >= w[0] - 1e-12), "{map:?}");
    }
    assert_eq!(Colormap::Bone.rgb(0.0), [0.0, 0.0, 0.0]);
    let b = Colormap::Bone.rgb(0.365079);
    assert!(
        (b[1] - 0.319444).abs() < 1e-9 && (b[2] - 0.444444).abs() < 1e-9,
        "{b:?}"
    );
    let h = Colormap::Hot.rgb(0.0);
    assert_eq!(h, [0.0416, 0.0, 0.0]);
    let h = Colormap::Hot.rgb(0.746032);
    assert!(
        (h[0] - 1.0).abs() < 1e-12 && (h[1] - 1.0).abs() < 1e-9 && h[2].abs() < 1e-9,
        "{h:?}"
    );
    assert_eq!("bone".parse::<Colormap>(), Ok(Colormap::Bone));
    assert!("jet"
        .parse::<Colormap>()
        .unwrap_err()
        .contains("gray, bone or hot"));
}

#[test]
fn colormapped_png_is_rgb_in_8_and_16_bits() {
    let dir = temp_dir("rgb");
    let pixels = [0.0, 0.5, 1.0, 0.25];
    for bits in [Bits::Eight, Bits::Sixteen] {
        let style = Style {
            bits,
            window: Window::Range(0.0, 1.0),
            colormap: Colormap::Hot,
        };
        let path = dir.join(format!("hot{bits:?}.png"));
        write_png(&path, 2, 2, &pixels, &style).unwrap();
        let (info, frames) = png_frames(&path);
        assert_eq!(info.color_type, png::ColorType::Rgb);
        let per = if bits == Bits::Eight { 1 } else { 2 };
        assert_eq!(frames[0].len(), 4 * 3 * per);
        let full: f64 = if bits == Bits::Eight { 255.0 } else { 65535.0 };
        let first_red = if per == 1 {
            frames[0][0] as f64
        } else {
            u16::from_be_bytes([frames[0][0], frames[0][1]]) as f64
        };
        assert_eq!(first_red, (0.0416 * full).round());
    }
}

#[test]
fn apng_holds_every_frame_with_one_window_and_loops() {
    let dir = temp_dir("apng");
    let frames: Vec<Vec<f64>> = (0..5).map(|k| vec![k as f64; 6]).collect();
    let path = dir.join("spin.apng");
    write_apng(
        &path,
        3,
        2,
        &frames,
        12,
        &Style {
            window: Window::Percentiles(0.0, 100.0),
            ..Style::default()
        },
    )
    .unwrap();
    let (info, decoded) = png_frames(&path);
    let actl = info.animation_control.expect("animated");
    assert_eq!((actl.num_frames, actl.num_plays), (5, 0));
    assert_eq!(decoded.len(), 5);
    for (k, frame) in decoded.iter().enumerate() {
        // One window over all frames: frame k is k/4 of the way to white.
        let expected = (k as f64 / 4.0 * 255.0).round() as u8;
        assert_eq!(frame, &vec![expected; 6], "frame {k}");
    }
    let err = write_apng(&path, 3, 2, &[], 12, &Style::default()).unwrap_err();
    assert!(
        err.contains("no frames") && err.contains("spin.apng"),
        "{err}"
    );
    let err = write_apng(&path, 3, 3, &frames, 12, &Style::default()).unwrap_err();
    assert!(err.contains("6 pixels in a 3x3"), "{err}");
    let err = write_png(
        &dir.join("missing/x.png"),
        3,
        2,
        &frames[0],
        &Style::default(),
    )
    .unwrap_err();
    assert!(err.contains("missing/x.png"), "{err}");
}

#[test]
fn orbit_turns_the_start_direction_about_the_axis() {
    let views = orbit([1.0, 0.0, 0.5], [0.0, 0.0, 2.0], 4).unwrap();
    let expected = [
        [1.0, 0.0, 0.5],
        [0.0, 1.0, 0.5],
        [-1.0, 0.0, 0.5],
        [0.0, -1.0, 0.5],
    ];
    for (v, e) in views.iter().zip(expected) {
        for i in 0..3 {
            assert!((v.dir[i] - e[i]).abs() < 1e-12, "{:?} vs {e:?}", v.dir);
        }
        assert_eq!(v.up, [0.0, 0.0, 2.0]);
    }
    assert!(
        orbit([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], 8).is_err(),
        "parallel"
    );
    assert!(
        orbit([1.0, 0.0, 0.0], [0.0, 0.0, 0.0], 8).is_err(),
        "zero axis"
    );
    assert!(orbit([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], 0)
        .unwrap_err()
        .contains("at least 1 frame"));
}

#[test]
fn turntable_frames_equal_single_renders_of_the_same_views() {
    let volume = sample(&GaussianMixture::random(3, 32, 4), [32, 32, 32]);
    let filter = Filter::new(FilterKind::Kb4, 1).unwrap();
    let views = orbit([1.0, 0.3, 0.2], [0.0, 0.0, 1.0], 6).unwrap();
    for precision in [Precision::F16, Precision::F64] {
        let spec = AnySpectrum::prepare(&volume, filter, precision).unwrap();
        let done = std::sync::atomic::AtomicUsize::new(0);
        let progress = || {
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        };
        let frames = render_views(&spec, &views, &Sampling::UNIT, 32, 24, &progress).unwrap();
        assert_eq!(done.into_inner(), 6);
        for (view, frame) in views.iter().zip(&frames) {
            assert_eq!(frame, &spec.render(view, 32, 24).unwrap(), "{precision}");
        }
        // Different views give different images (the orbit really turns).
        assert_ne!(frames[0], frames[1]);
    }
}

/// The selected ranks are the sorted values' at the same nearest ranks, on
/// shuffled values with repeats, for every pair of percentiles on a grid.
#[test]
fn percentiles_are_the_sorted_values_ranks() {
    let mut state = 12345u64;
    for len in [1usize, 2, 7, 100, 1001] {
        let pixels: Vec<f64> = (0..len)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 40) % 50) as f64 - 20.0
            })
            .collect();
        let mut sorted = pixels.clone();
        sorted.sort_by(f64::total_cmp);
        let at = |p: f64| sorted[((p / 100.0) * (len - 1) as f64).round() as usize];
        for lo in [0.0, 0.5, 10.0, 50.0] {
            for hi in [50.5, 90.0, 99.5, 100.0] {
                let (a, b) = (at(lo), at(hi));
                let expected = if b > a { (a, b) } else { (a, a + 1.0) };
                assert_eq!(
                    percentile_range(&pixels, lo, hi),
                    expected,
                    "{len} {lo} {hi}"
                );
            }
        }
    }
}
