//! Unit tests of the scene-file checker.

use super::*;

fn parse(text: &str) -> Result<SceneFile, String> {
    SceneFile::parse(text, "s.toml", Path::new("/scenes"))
}

#[test]
fn edit_distance_counts_insertions_deletions_and_substitutions() {
    assert_eq!(edit_distance("", ""), 0);
    assert_eq!(edit_distance("color", "color"), 0);
    assert_eq!(edit_distance("colr", "color"), 1);
    assert_eq!(edit_distance("colour", "color"), 1);
    assert_eq!(edit_distance("kitten", "sitting"), 3);
    assert_eq!(edit_distance("", "abc"), 3);
    assert_eq!(edit_distance("abc", ""), 3);
    assert_eq!(closest_key("dirn", CAMERA_KEYS), Some("dir"));
    assert_eq!(closest_key("colour", LIGHT_KEYS), Some("color"));
}

#[test]
fn full_scene_parses_every_key() {
    let s = parse(include_str!("../../tests/data/every-key.toml")).unwrap();
    assert_eq!(s.volume.spec.as_deref(), Some("/scenes/v.raw"));
    assert_eq!(s.volume.raw_dims, Some([4, 5, 6]));
    assert_eq!(s.volume.raw_type, Some(SampleType::U16));
    assert_eq!(s.volume.raw_endian, Some(Endian::Big));
    assert_eq!(s.volume.background, Some(-1024.0));
    assert_eq!(s.volume.resample, Some(96));
    assert_eq!(s.camera.dir, Some([1.0, 0.5, -0.25]));
    assert_eq!(s.camera.up, Some([0.0, 1.0, 0.0]));
    assert_eq!(s.camera.size, Some((64, 32)));
    assert_eq!(s.camera.pixel_size, Some(0.5));
    assert_eq!(s.volume.ignore_spacing, Some(false));
    assert_eq!(s.spectrum.filter, Some(FilterKind::Cubic));
    assert_eq!(s.spectrum.oversample, Some(GridOversampling::X2));
    assert_eq!(s.spectrum.precision, Some(Precision::F32));
    assert_eq!(s.spectrum.kb_design, Some(KbDesign::Sigma(1.5)));
    assert_eq!(s.shading.ambient, Some([0.1; 3]));
    assert_eq!(s.shading.depth_cue.as_deref(), Some("linear:1,0.3"));
    assert_eq!(s.shading.cue_harmonics, Some(6));
    assert_eq!(s.shading.cue_correction, Some(false));
    assert_eq!(s.light_ring, Some((2, 10.0)));
    assert_eq!(
        s.lights,
        Some(vec![Light {
            towards: [0.0, 1.0, 0.0],
            color: [1.0, 0.0, 0.0]
        }])
    );
    assert_eq!(s.output.path, Some(PathBuf::from("/scenes/a.png")));
    assert_eq!(s.output.bits, Some(Bits::Sixteen));
    assert_eq!((s.output.window, s.output.level), (Some(2.0), Some(1.0)));
    assert_eq!(s.output.colormap, Some(Colormap::Bone));
    assert_eq!(s.turntable.frames, Some(12));
    assert_eq!(s.turntable.path, Some(PathBuf::from("/scenes/spin.apng")));
}

#[test]
fn empty_scene_sets_nothing_and_builtin_names_stay_names() {
    assert_eq!(parse("").unwrap(), SceneFile::default());
    let s = parse("[volume]\nbuiltin = \"teapot@64\"\n[camera]\nsize = 48\n").unwrap();
    assert_eq!(s.volume.spec.as_deref(), Some("teapot@64"));
    assert_eq!(s.camera.size, Some((48, 48)));
}

#[test]
fn unknown_keys_name_the_path_and_the_closest_key() {
    let e = parse(
        "[[lights]]\ndirection = [0,1,0]\ncolor = 1\n[[lights]]\ndirection = [1,0,0]\ncolr = [1,0,0]\n",
    )
    .unwrap_err();
    assert!(e.contains("s.toml: unknown key `lights[1].colr`"), "{e}");
    assert!(e.contains("closest valid key is `lights[1].color`"), "{e}");
    assert!(e.contains("`lights[1]`: needs a `color`"), "{e}");
    let e = parse("[camera]\ndirection = [1,0,0]\n").unwrap_err();
    assert!(e.contains("unknown key `camera.direction`"), "{e}");
    assert!(e.contains("`camera.dir`"), "{e}");
    let e = parse("[ouput]\npath = \"a.png\"\n").unwrap_err();
    assert!(e.contains("unknown key `ouput`"), "{e}");
    assert!(e.contains("closest valid key is `output`"), "{e}");
}

#[test]
fn every_problem_is_reported_once_per_line() {
    let e =
        parse("[camera]\ndir = \"x\"\nup = [0, 0]\n[spectrum]\nfilter = \"kb9\"\n").unwrap_err();
    let lines: Vec<&str> = e.lines().collect();
    assert_eq!(lines.len(), 3, "{e}");
    assert!(lines.iter().all(|l| l.starts_with("s.toml: ")), "{e}");
    assert!(
        e.contains("`camera.dir` must be an array of 3 numbers, got string \"x\""),
        "{e}"
    );
    assert!(e.contains("`camera.up`: must be an array of 3 numbers, got 2 elements"));
    assert!(e.contains("`spectrum.filter`: unknown filter `kb9`"), "{e}");
}

#[test]
fn wrong_types_name_the_key_and_the_expected_type() {
    for (text, needle) in [
        (
            "[spectrum]\noversample = \"2\"",
            "`spectrum.oversample` must be 1, 1.25, 1.5 or 2, got string \"2\"",
        ),
        (
            "[spectrum]\noversample = 3",
            "`spectrum.oversample` must be 1, 1.25, 1.5 or 2, got integer 3",
        ),
        (
            "[output]\nbits = 12",
            "`output.bits` must be 8 or 16, got integer 12",
        ),
        (
            "[shading]\ncue_correction = 1",
            "`shading.cue_correction` must be true or false",
        ),
        (
            "[volume]\nignore_spacing = true\n[camera]\npixel_size = 0.5",
            "`camera.pixel_size`: conflicts with `volume.ignore_spacing = true`",
        ),
        (
            "[shading]\nambient = [1, \"a\", 0]",
            "`shading.ambient[1]` must be a finite number",
        ),
        (
            "[shading]\nambient = -1",
            "`shading.ambient`: colours must be >= 0",
        ),
        ("volume = 3", "`volume` must be a table, got integer 3"),
        ("lights = 3", "`lights` must be an array of tables"),
        (
            "[camera]\ndir = [0, 0, 0]",
            "`camera.dir`: must not be the zero vector",
        ),
        (
            "[camera]\nsize = [64, 0]",
            "`camera.size`: must be positive integers",
        ),
        (
            "[camera]\nsize = 1.5",
            "`camera.size` must be an integer or an array",
        ),
        ("[volume]\npath = \"a\"\nbuiltin = \"b\"", "not both"),
        ("[output]\nwindow = 1", "`window` and `level` go together"),
        ("[output]\npercentiles = [50, 10]", "`output.percentiles`"),
        ("[shading]\ndepth_cue = \"linear:1\"", "`shading.depth_cue`"),
        ("[light_ring]\ntilt = 10", "`light_ring`: needs a `count`"),
        (
            "[light_ring]\ncount = 9",
            "`light_ring.count`: must be from 1 to 8",
        ),
        (
            "[volume]\nraw_endian = \"middle\"",
            "`volume.raw_endian`: unknown byte order",
        ),
    ] {
        let e = parse(text).unwrap_err();
        assert!(e.contains(needle), "{text}: `{needle}` not in {e}");
    }
}

#[test]
fn too_many_lights_and_bad_toml_are_errors() {
    let mut text = String::from("[light_ring]\ncount = 3\n");
    for _ in 0..6 {
        text.push_str("[[lights]]\ndirection = [0,1,0]\ncolor = 1\n");
    }
    let e = parse(&text).unwrap_err();
    assert!(e.contains("make 9 lights"), "{e}");
    let e = parse("[camera\n").unwrap_err();
    assert!(
        e.starts_with("s.toml: not valid TOML at line 1, column "),
        "{e}"
    );
    assert_eq!(e.lines().count(), 1, "{e}");
    // A 900 000-digit number: one short line, not the line echoed whole.
    let e = parse(&format!(
        "[camera]\ndir = [{}, 0, 0]\n",
        "1".repeat(900_000)
    ))
    .unwrap_err();
    assert!(
        e.starts_with("s.toml: not valid TOML at line 2, column 8: "),
        "{e}"
    );
    assert!(e.len() < 200, "{} bytes", e.len());
}

#[test]
fn missing_file_names_it() {
    let e = SceneFile::load(Path::new("/nonexistent/scene.toml")).unwrap_err();
    assert!(
        e.contains("cannot read scene file `/nonexistent/scene.toml`"),
        "{e}"
    );
}

#[test]
fn profile_cue_file_is_relative_to_the_scene() {
    let dir = std::env::temp_dir().join(format!("fvr-scene-profile-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("w.txt"), "1, 0.5\n").unwrap();
    let s = SceneFile::parse(
        "[shading]\ndepth_cue = \"profile:@w.txt\"\n",
        "s.toml",
        &dir,
    )
    .unwrap();
    assert_eq!(
        s.shading.depth_cue,
        Some(format!("profile:@{}", dir.join("w.txt").display()))
    );
    assert!(parse("[shading]\ndepth_cue = \"profile:@w.txt\"\n").is_err());
}
