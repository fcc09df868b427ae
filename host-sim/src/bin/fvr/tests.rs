//! The scene-file merge against the parsed command line.

use super::*;
use crate::render::RenderArgs;
use crate::scene::{given_on_command_line, FromScene};
use clap::ArgMatches;
use fvr_core::filter::FilterKind;
use fvr_core::shading::Light;
use fvr_core::volume::GridOversampling;
use fvr_engine::plan::filter::KbDesign;
use fvr_engine::spectrum::Precision;
use fvr_host::io::nrrd::{Endian, SampleType};
use std::path::PathBuf;

/// A scene that sets every key `fvr render` reads.
const FULL_SCENE: &str = include_str!("../../../tests/data/every-key.toml");

fn parse_cli(argv: &[&str]) -> (Cli, ArgMatches) {
    let m = Cli::command()
        .try_get_matches_from(argv)
        .expect("arguments parse");
    (Cli::from_arg_matches(&m).expect("arguments convert"), m)
}

/// Parse `fvr SUB --scene s.toml FLAGS`, pick the subcommand's arguments
/// and fill them from the scene `text` (read from `/s`).
fn merged<A: FromScene>(
    sub: &str,
    text: &str,
    flags: &[&str],
    pick: impl FnOnce(Command) -> Option<A>,
) -> A {
    let mut argv = vec!["fvr", sub, "--scene", "s.toml"];
    argv.extend(flags);
    let (cli, m) = parse_cli(&argv);
    let mut args = cli.command.and_then(pick).expect("the subcommand");
    let matches = m.subcommand_matches(sub).expect("subcommand matches");
    let scene = SceneFile::parse(text, "s.toml", Path::new("/s")).expect("scene parses");
    args.apply_scene(&scene, &|id| given_on_command_line(matches, id));
    args
}

fn merged_render(scene: &str, flags: &[&str]) -> RenderArgs {
    merged("render", scene, flags, |c| match c {
        Command::Render(args) => Some(*args),
        _ => None,
    })
}

#[test]
fn scene_fills_every_render_setting() {
    let a = merged_render(FULL_SCENE, &[]);
    assert_eq!(a.volume.as_deref(), Some("/s/v.raw"));
    assert_eq!(a.input.raw_dims, Some([4, 5, 6]));
    assert_eq!(a.input.raw_type, SampleType::U16);
    assert_eq!(a.input.raw_endian, Endian::Big);
    assert_eq!(a.input.background, Some(-1024.0));
    assert_eq!(a.look.resample, Some(96));
    assert_eq!(a.dir, Some([1.0, 0.5, -0.25]));
    assert_eq!(a.up, [0.0, 1.0, 0.0]);
    assert_eq!(a.frame.size, Some((64, 32)));
    assert_eq!(a.frame.units.pixel_size, Some(0.5));
    assert!(!a.frame.units.ignore_spacing);
    assert_eq!(a.frame.spectrum.filter, FilterKind::Cubic);
    assert_eq!(a.frame.spectrum.oversample, GridOversampling::X2);
    assert_eq!(a.frame.spectrum.precision, Precision::F32);
    assert_eq!(a.frame.spectrum.kb_design, KbDesign::Sigma(1.5));
    assert_eq!(a.look.ambient, Some([0.1; 3]));
    assert_eq!(a.look.depth_cue, "linear:1,0.3");
    assert_eq!(a.look.cue_harmonics, 6);
    assert!(a.look.no_cue_correction);
    assert_eq!(a.look.light_ring, Some((2, 10.0)));
    assert_eq!(
        a.look.lights,
        vec![Light {
            towards: [0.0, 1.0, 0.0],
            color: [1.0, 0.0, 0.0]
        }]
    );
    assert_eq!(a.out.as_deref(), Some(Path::new("/s/a.png")));
    assert_eq!(a.png.bits, Bits::Sixteen);
    assert_eq!((a.png.window, a.png.level), (Some(2.0), Some(1.0)));
    assert_eq!(a.png.colormap, Colormap::Bone);
    // An empty scene leaves the flags' defaults.
    let d = merged_render("", &["v.nrrd", "--dir", "0,1,0", "--out", "o.png"]);
    assert_eq!(d.frame.spectrum.filter, FilterKind::Kb4);
    assert_eq!(d.up, DEFAULT_UP);
    assert_eq!(d.look.depth_cue, "none");
    assert!(!d.look.no_cue_correction && d.look.lights.is_empty() && d.look.light_ring.is_none());
}

#[test]
fn each_flag_overrides_its_scene_key() {
    type Check = fn(&RenderArgs) -> bool;
    let cases: &[(&[&str], Check)] = &[
        (&["other.nrrd"], |a| {
            a.volume.as_deref() == Some("other.nrrd") && a.input.raw_dims.is_none()
        }),
        (&["--raw-dims", "7,8,9"], |a| {
            a.input.raw_dims == Some([7, 8, 9])
        }),
        (&["--raw-type", "f32"], |a| {
            a.input.raw_type == SampleType::F32
        }),
        (&["--raw-endian", "little"], |a| {
            a.input.raw_endian == Endian::Little
        }),
        (&["--background", "0"], |a| a.input.background == Some(0.0)),
        (&["--resample", "64"], |a| a.look.resample == Some(64)),
        (&["--dir", "0,0,1"], |a| a.dir == Some([0.0, 0.0, 1.0])),
        (&["--up", "1,0,0"], |a| a.up == [1.0, 0.0, 0.0]),
        (&["--size", "8"], |a| a.frame.size == Some((8, 8))),
        (&["--pixel-size", "2"], |a| {
            a.frame.units.pixel_size == Some(2.0)
        }),
        (&["--ignore-spacing"], |a| {
            a.frame.units.ignore_spacing && a.frame.units.pixel_size.is_none()
        }),
        (&["--filter", "kb3"], |a| {
            a.frame.spectrum.filter == FilterKind::Kb3
        }),
        (&["--oversample", "1.25"], |a| {
            a.frame.spectrum.oversample == GridOversampling::X1_25
        }),
        (&["--precision", "f16"], |a| {
            a.frame.spectrum.precision == Precision::F16
        }),
        (&["--kb-design", "auto"], |a| {
            a.frame.spectrum.kb_design == KbDesign::Auto
        }),
        (&["--ambient", "0.5"], |a| a.look.ambient == Some([0.5; 3])),
        (&["--depth-cue", "none"], |a| a.look.depth_cue == "none"),
        (&["--cue-harmonics", "3"], |a| a.look.cue_harmonics == 3),
        (&["--light", "1,0,0:0,0,1"], |a| {
            a.look.lights
                == [Light {
                    towards: [1.0, 0.0, 0.0],
                    color: [0.0, 0.0, 1.0],
                }]
        }),
        (&["--light-ring", "3"], |a| {
            a.look.light_ring == Some((3, 30.0))
        }),
        (&["--out", "x.nrrd"], |a| {
            a.out.as_deref() == Some(Path::new("x.nrrd"))
        }),
        (&["--bits", "8"], |a| a.png.bits == Bits::Eight),
        (&["--window", "4", "--level", "3"], |a| {
            (a.png.window, a.png.level) == (Some(4.0), Some(3.0))
        }),
        (&["--percentiles", "1,99"], |a| {
            a.png.percentiles == (1.0, 99.0) && a.png.window.is_none()
        }),
        (&["--colormap", "hot"], |a| a.png.colormap == Colormap::Hot),
    ];
    let scene_only = merged_render(FULL_SCENE, &[]);
    for (flags, check) in cases {
        assert!(!check(&scene_only), "{flags:?} matches the scene already");
        assert!(check(&merged_render(FULL_SCENE, flags)), "{flags:?}");
    }
    // --no-cue-correction is a switch: the scene turns it on, the flag
    // cannot turn it off, and an unset scene key leaves it to the flag.
    let on = "[shading]\ncue_correction = true\n";
    assert!(
        merged_render(on, &["--no-cue-correction"])
            .look
            .no_cue_correction
    );
    assert!(!merged_render(on, &[]).look.no_cue_correction);
}

#[test]
fn turntable_takes_scene_values_and_flags_win() {
    let run = |flags: &[&str]| {
        merged("turntable", FULL_SCENE, flags, |c| match c {
            Command::Turntable(args) => Some(*args),
            _ => None,
        })
    };
    let a = run(&[]);
    assert_eq!((a.frames, a.fps), (12, 6));
    assert_eq!(a.out, PathBuf::from("/s/spin.apng"));
    assert_eq!(a.dir, [1.0, 0.5, -0.25]);
    assert_eq!(a.frame.spectrum.filter, FilterKind::Cubic);
    // The scene's shading, lights and resampling, as for a render.
    assert_eq!(a.look.resample, Some(96));
    assert_eq!(a.look.depth_cue, "linear:1,0.3");
    assert_eq!(a.look.light_ring, Some((2, 10.0)));
    assert_eq!(a.look.ambient, Some([0.1; 3]));
    let b = run(&[
        "--frames", "3", "--fps", "30", "--out", "t.apng", "--dir", "0,1,0",
    ]);
    assert_eq!((b.frames, b.fps), (3, 30));
    assert_eq!(b.out, PathBuf::from("t.apng"));
    assert_eq!(b.dir, [0.0, 1.0, 0.0]);
}

#[test]
fn default_scene_is_a_valid_scene() {
    let scene = SceneFile::parse(DEFAULT_SCENE, "default", Path::new("")).expect("parses");
    assert!(scene.volume.spec.is_some() && scene.camera.dir.is_some());
    assert_eq!(scene.output.path, Some(PathBuf::from("fvr-default.png")));
}
