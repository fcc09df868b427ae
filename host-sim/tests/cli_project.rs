//! `fvr project`: a stack of views from one preparation, each frame the
//! image `fvr render` writes for that view, bit for bit.

mod common;
use common::{assert_error, fvr_line, fvr_ok, temp_dir};
use std::path::Path;

/// The float32 payload of a NRRD file written by fvr (raw, little endian:
/// everything after the blank line that ends the header).
fn nrrd_payload(path: &Path) -> (String, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .expect("a NRRD header")
        + 2;
    (
        String::from_utf8_lossy(&bytes[..end]).into_owned(),
        bytes[end..].to_vec(),
    )
}

#[test]
fn every_frame_is_the_render_of_its_view_bit_for_bit() {
    let dir = temp_dir("project-bits");
    let views = "dx,dy,dz,ux,uy,uz\n1,0.45,0.3\n0,0,1,0,1,0\n# diagonal\n-1 1 1\n";
    std::fs::write(dir.join("v.csv"), views).unwrap();
    let out = fvr_ok(
        "project gaussians@32 --views v.csv --out s.nrrd --quiet",
        &dir,
    );
    assert!(
        out.contains("wrote s.nrrd (3 views of 32x32 grey)"),
        "{out}"
    );
    let (header, stack) = nrrd_payload(&dir.join("s.nrrd"));
    assert!(header.contains("sizes: 32 32 3\n"), "{header}");
    assert!(header.contains("kinds: space space list\n"), "{header}");
    assert_eq!(stack.len(), 3 * 32 * 32 * 4);
    for (i, (d, u)) in [
        ("1,0.45,0.3", "0,0,1"),
        ("0,0,1", "0,1,0"),
        ("-1,1,1", "0,0,1"),
    ]
    .iter()
    .enumerate()
    {
        let line = format!("render gaussians@32 --dir {d} --up {u} --out r{i}.nrrd --quiet");
        fvr_ok(&line, &dir);
        let (_, image) = nrrd_payload(&dir.join(format!("r{i}.nrrd")));
        let frame = &stack[i * image.len()..(i + 1) * image.len()];
        assert!(
            frame == image.as_slice(),
            "view {i} differs from fvr render"
        );
        // Not vacuous: the frame has content.
        assert!(image
            .chunks(4)
            .any(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) > 0.0));
    }
}

/// `--zoom F`: every frame is `fvr render --zoom F`'s image of its view
/// bit for bit, F times as wide and high, with the pixel size over F; and
/// lit or cued scenes are not a question here (project renders X-rays).
#[test]
fn zoomed_frames_are_the_zoomed_renders() {
    let dir = temp_dir("project-zoom");
    std::fs::write(dir.join("v.csv"), "1,0.45,0.3\n-1,1,1,0.2,0.3,1\n").unwrap();
    let out = fvr_ok(
        "project gaussians@32 --views v.csv --zoom 2 --out s.nrrd --quiet",
        &dir,
    );
    assert!(out.contains("(2 views of 64x64 grey)"), "{out}");
    let (header, stack) = nrrd_payload(&dir.join("s.nrrd"));
    assert!(header.contains("sizes: 64 64 2\n"), "{header}");
    let (plain_header, _) = {
        let line = "project gaussians@32 --views v.csv --out p.nrrd --quiet";
        fvr_ok(line, &dir);
        nrrd_payload(&dir.join("p.nrrd"))
    };
    let spacing = |h: &str| -> f64 {
        let line = h
            .lines()
            .find(|l| l.starts_with("spacings:"))
            .expect("spacings");
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    };
    assert_eq!(spacing(&header) * 2.0, spacing(&plain_header), "{header}");
    for (i, (d, u)) in [("1,0.45,0.3", "0,0,1"), ("-1,1,1", "0.2,0.3,1")]
        .iter()
        .enumerate()
    {
        let line =
            format!("render gaussians@32 --dir {d} --up {u} --zoom 2 --out r{i}.nrrd --quiet");
        fvr_ok(&line, &dir);
        let (_, image) = nrrd_payload(&dir.join(format!("r{i}.nrrd")));
        assert_eq!(image.len(), 64 * 64 * 4);
        let frame = &stack[i * image.len()..(i + 1) * image.len()];
        assert!(
            frame == image.as_slice(),
            "view {i} differs from fvr render --zoom 2"
        );
    }
    // A zoom the transforms do not serve is refused before any work.
    let out = fvr_line(
        "project gaussians@32 --random 2 --zoom 7 --out z.nrrd",
        &dir,
    );
    assert_error(&out, &["--zoom", "prime factor"]);
    assert!(!dir.join("z.nrrd").exists());
}

#[test]
fn random_views_are_saved_and_read_back_to_the_same_stack_in_npy() {
    let dir = temp_dir("project-random");
    fvr_ok(
        "project sphere@16 --random 5 --seed 3 --size 12 --save-views v.csv --out a.npy --quiet",
        &dir,
    );
    fvr_ok(
        "project sphere@16 --views v.csv --size 12 --out b.nrrd --quiet",
        &dir,
    );
    let a = std::fs::read(dir.join("a.npy")).unwrap();
    assert_eq!(&a[..8], b"\x93NUMPY\x01\x00");
    let len = u16::from_le_bytes([a[8], a[9]]) as usize;
    let dict = String::from_utf8_lossy(&a[10..10 + len]);
    assert!(dict.contains("'descr': '<f4'"), "{dict}");
    assert!(dict.contains("'shape': (5, 12, 12)"), "{dict}");
    let (_, b) = nrrd_payload(&dir.join("b.nrrd"));
    assert!(
        a[10 + len..] == b[..],
        "the saved views render the same stack"
    );
    // Another seed, other views.
    fvr_ok(
        "project sphere@16 --random 5 --seed 4 --size 12 --out c.npy --quiet",
        &dir,
    );
    assert_ne!(std::fs::read(dir.join("c.npy")).unwrap(), a);
    let csv = std::fs::read_to_string(dir.join("v.csv")).unwrap();
    assert_eq!(csv.lines().count(), 6, "{csv}");
}

#[test]
fn stats_json_is_alone_on_stdout() {
    let dir = temp_dir("project-json");
    let out = fvr_ok(
        "project sphere@16 --random 3 --out s.npy --stats-json --quiet",
        &dir,
    );
    assert_eq!(out.lines().count(), 1, "{out}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(v["views"], 3);
    assert_eq!(v["image"], serde_json::json!([16, 16, 1]));
    assert!(v["ms_per_view"].as_f64().unwrap() > 0.0);
    assert!(v["accuracy"]["predicted_db"].as_f64().is_some(), "{v}");
}

/// `--stats-json` counts the views each slice walk took: views containing
/// an axis are factored along it (`column`), rows along an axis are
/// reduced along it (`strip`), and the counts cover every view; `--stats`
/// prints the same counts.
#[test]
fn stats_name_the_walk_of_every_view() {
    let dir = temp_dir("project-walks");
    std::fs::write(dir.join("v.csv"), "1,0,0\n0,1,0\n1,0.3,0\n1,0.3,0.2\n").unwrap();
    let base = "project gaussians@32 --views v.csv --out s.nrrd --quiet";
    let out = fvr_ok(&format!("{base} --stats-json"), &dir);
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(
        v["walks"],
        serde_json::json!({"column": 3, "strip": 1}),
        "{v}"
    );
    let out = fvr_ok(&format!("{base} --stats"), &dir);
    assert!(out.contains("walks         column 3, strip 1"), "{out}");
    let out = fvr_ok(
        "project gaussians@32 --random 5 --out r.nrrd --stats-json --quiet",
        &dir,
    );
    let v: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    let counts = v["walks"].as_object().expect("walks");
    assert_eq!(
        counts.values().filter_map(|c| c.as_u64()).sum::<u64>(),
        5,
        "{v}"
    );
}

/// `--filter`, `--oversample` and `--precision` are kept as given, each
/// alone (the planner chooses the rest) and all three (none chosen), as
/// `render` keeps them; they were once dropped for the planner's choice.
#[test]
fn the_spectrum_flags_given_are_kept() {
    let dir = temp_dir("project-given");
    let base = "project gaussians@32 --random 2 --seed 1 --out g.nrrd --stats-json --quiet";
    for (flags, key, value) in [
        ("--filter linear", "filter", serde_json::json!("linear")),
        ("--filter kb3", "filter", serde_json::json!("kb3")),
        ("--oversample 2", "oversample", serde_json::json!(2)),
        ("--precision f64", "precision", serde_json::json!("f64")),
    ] {
        let (v, _) = common::stats_json(&format!("{base} {flags}"), &dir);
        assert_eq!(v[key], value, "{flags}: {v}");
    }
    let all = format!("{base} --filter cubic --oversample 1 --precision f32");
    let (v, _) = common::stats_json(&all, &dir);
    let chosen = (
        v["filter"].clone(),
        v["oversample"].clone(),
        v["precision"].clone(),
    );
    let want = (
        serde_json::json!("cubic"),
        serde_json::json!(1),
        serde_json::json!("f32"),
    );
    assert_eq!(chosen, want, "{v}");
}

#[test]
fn bad_views_and_outputs_are_one_line_and_write_nothing() {
    let dir = temp_dir("project-bad");
    std::fs::write(dir.join("bad.csv"), "1,0,0\n0,zero,1\n").unwrap();
    std::fs::write(dir.join("par.csv"), "1,0,0\n0,0,1\n").unwrap();
    std::fs::write(
        dir.join("bad.json"),
        r#"[{"dir": [1,0,0], "upp": [0,0,1]}]"#,
    )
    .unwrap();
    std::fs::write(dir.join("empty.csv"), "# nothing\n").unwrap();
    for (line, needles) in [
        (
            "project sphere@16 --views bad.csv --out s.nrrd",
            &["bad.csv: line 2: `zero` is not a number"][..],
        ),
        (
            "project sphere@16 --views par.csv --out s.nrrd",
            &["view 1", "parallel"][..],
        ),
        (
            "project sphere@16 --views bad.json --out s.nrrd",
            &["unknown key `upp`"][..],
        ),
        (
            "project sphere@16 --views empty.csv --out s.nrrd",
            &["no views"][..],
        ),
        (
            "project sphere@16 --views nope.csv --out s.nrrd",
            &["nope.csv"][..],
        ),
        (
            "project sphere@16 --random 2 --out s.png",
            &["must end in .nrrd or .npy"][..],
        ),
        (
            "project sphere@16 --views bad.csv --out bad.csv",
            &["must end in .nrrd or .npy"][..],
        ),
        (
            "project sphere@16 --random 0 --out s.nrrd",
            &["--random"][..],
        ),
        (
            "project sphere@16 --random 2 --views par.csv --out s.nrrd",
            &["cannot be used with"][..],
        ),
        ("project sphere@16 --out s.nrrd", &["--views"][..]),
    ] {
        let out = fvr_line(line, &dir);
        assert_error(&out, needles);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{line}: {err}");
        assert!(!dir.join("s.nrrd").exists(), "{line}");
    }
    // The views file named as the output was left as it was.
    assert_eq!(
        std::fs::read_to_string(dir.join("bad.csv")).unwrap(),
        "1,0,0\n0,zero,1\n"
    );
}

/// Views whose frames overflow f32 are refused by the job's view number,
/// with the command line's advice, and no stack is written.
#[test]
fn frames_that_overflow_f32_are_refused_by_view_number() {
    let dir = temp_dir("project-overflow");
    // A smooth 8³ blob near f32::MAX: its line integrals exceed f32.
    let data: Vec<u8> = (0..512)
        .flat_map(|i: usize| {
            let (x, y, z) = (i % 8, (i / 8) % 8, i / 64);
            let r2 = [x, y, z]
                .map(|c| (c as f32 - 3.5) / 3.5)
                .iter()
                .map(|d| d * d)
                .sum::<f32>();
            (3e38f32 * (1.0 - r2 / 3.0)).to_le_bytes()
        })
        .collect();
    std::fs::write(dir.join("hot.raw"), data).unwrap();
    let out = fvr_line(
        "project hot.raw --raw-dims 8,8,8 --raw-type f32 --random 3 --seed 1 --out s.nrrd",
        &dir,
    );
    assert_error(
        &out,
        &[
            "view 0 has non-finite pixels",
            "rescale the volume, or add --ignore-spacing",
        ],
    );
    // Magnified, the same refusal by the same view.
    let out = fvr_line(
        "project hot.raw --raw-dims 8,8,8 --raw-type f32 --random 3 --seed 1 --zoom 2 --out s.nrrd",
        &dir,
    );
    assert_error(
        &out,
        &[
            "view 0 has non-finite pixels",
            "rescale the volume, or add --ignore-spacing",
        ],
    );
    assert!(!dir.join("s.nrrd").exists());
}
