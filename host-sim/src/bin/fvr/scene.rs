//! Merging a scene file into the command line: flags win, then the
//! scene's keys, then the flags' defaults.

use crate::args::{InputArgs, PngArgs, SpectrumArgs, UnitArgs};
use crate::render::RenderArgs;
use crate::turntable::TurntableArgs;
use crate::Error;

use std::path::Path;

use clap::parser::ValueSource;
use clap::ArgMatches;
use fvr_host::scene_file::SceneFile;

/// Whether the argument `id` was given on the command line (not defaulted).
pub(crate) fn given_on_command_line(matches: &ArgMatches, id: &str) -> bool {
    matches.try_get_raw(id).is_ok() && matches.value_source(id) == Some(ValueSource::CommandLine)
}

/// Set `slot` to the scene's `value` unless the flag `id` was given.
pub(crate) fn fill<T>(given: &dyn Fn(&str) -> bool, id: &str, slot: &mut T, value: Option<T>) {
    if let (false, Some(v)) = (given(id), value) {
        *slot = v;
    }
}

/// Fill the volume settings from the scene. A VOLUME given on the command
/// line drops the scene's raw layout, which describes the scene's file.
pub(crate) fn apply_scene_to_input(
    volume: &mut Option<String>,
    input: &mut InputArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    let v = &scene.volume;
    if !given("volume") {
        fill(given, "volume", volume, v.spec.clone().map(Some));
        fill(given, "raw_dims", &mut input.raw_dims, v.raw_dims.map(Some));
        fill(given, "raw_type", &mut input.raw_type, v.raw_type);
        fill(given, "raw_endian", &mut input.raw_endian, v.raw_endian);
    }
    fill(
        given,
        "background",
        &mut input.background,
        v.background.map(Some),
    );
}

/// Fill the physical-unit settings from the scene. A command-line choice of
/// either wins over the scene's other one, since the two conflict.
pub(crate) fn apply_scene_to_units(
    units: &mut UnitArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    if !given("ignore_spacing") {
        fill(
            given,
            "pixel_size",
            &mut units.pixel_size,
            scene.camera.pixel_size.map(Some),
        );
    }
    if !given("pixel_size") {
        fill(
            given,
            "ignore_spacing",
            &mut units.ignore_spacing,
            scene.volume.ignore_spacing,
        );
    }
}

pub(crate) fn apply_scene_to_spectrum(
    spectrum: &mut SpectrumArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    let s = &scene.spectrum;
    fill(given, "filter", &mut spectrum.filter, s.filter);
    fill(given, "oversample", &mut spectrum.oversample, s.oversample);
    fill(given, "precision", &mut spectrum.precision, s.precision);
    fill(given, "kb_design", &mut spectrum.kb_design, s.kb_design);
    fill(
        given,
        "accuracy",
        &mut spectrum.accuracy,
        s.accuracy.map(Some),
    );
    // A setting the scene fixes is the user's choice, as on the command line.
    spectrum.given.filter |= s.filter.is_some();
    spectrum.given.oversample |= s.oversample.is_some();
    spectrum.given.precision |= s.precision.is_some();
}

/// Fill the PNG settings. `--percentiles` on the command line also drops
/// the scene's window and level, which would otherwise take precedence.
pub(crate) fn apply_scene_to_png(
    png: &mut PngArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    let o = &scene.output;
    fill(given, "bits", &mut png.bits, o.bits);
    if !given("percentiles") && !given("window") && !given("level") {
        fill(given, "window", &mut png.window, o.window.map(Some));
        fill(given, "level", &mut png.level, o.level.map(Some));
    }
    fill(given, "percentiles", &mut png.percentiles, o.percentiles);
    fill(given, "colormap", &mut png.colormap, o.colormap);
}

/// Fill every render setting the command line did not give from the scene
/// (precedence: flags, then the scene, then the flags' defaults). Each flag
/// replaces the scene key of the same name: `--light` replaces all of the
/// scene's `[[lights]]`, `--light-ring` its `[light_ring]`.
pub(crate) fn apply_scene_to_render(
    args: &mut RenderArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    apply_scene_to_input(&mut args.volume, &mut args.input, scene, given);
    let c = &scene.camera;
    fill(given, "dir", &mut args.dir, c.dir.map(Some));
    fill(given, "up", &mut args.up, c.up);
    fill(given, "size", &mut args.frame.size, c.size.map(Some));
    apply_scene_to_units(&mut args.frame.units, scene, given);
    apply_scene_to_spectrum(&mut args.frame.spectrum, scene, given);
    crate::look::apply_scene_to_look(&mut args.look, scene, given);
    fill(
        given,
        "out",
        &mut args.out,
        scene.output.path.clone().map(Some),
    );
    apply_scene_to_png(&mut args.png, scene, given);
}

/// Fill the turntable settings the command line did not give from the
/// scene: volume, camera, spectrum, shading and lights, output window and
/// `[turntable]`. The scene's `output.path`, which a turntable does not
/// use, is named on stderr.
pub(crate) fn apply_scene_to_turntable(
    args: &mut TurntableArgs,
    scene: &SceneFile,
    given: &dyn Fn(&str) -> bool,
) {
    apply_scene_to_input(&mut args.volume, &mut args.input, scene, given);
    let c = &scene.camera;
    fill(given, "dir", &mut args.dir, c.dir);
    fill(given, "up", &mut args.up, c.up);
    fill(given, "size", &mut args.frame.size, c.size.map(Some));
    apply_scene_to_units(&mut args.frame.units, scene, given);
    apply_scene_to_spectrum(&mut args.frame.spectrum, scene, given);
    crate::look::apply_scene_to_look(&mut args.look, scene, given);
    apply_scene_to_png(&mut args.png, scene, given);
    let t = &scene.turntable;
    fill(given, "frames", &mut args.frames, t.frames);
    fill(given, "fps", &mut args.fps, t.fps);
    fill(given, "out", &mut args.out, t.path.clone());
    if scene.output.path.is_some() {
        eprintln!(
            "fvr: note: the turntable writes `turntable.path` (or --out), not the scene's \
             output.path"
        );
    }
}

pub(crate) const SCENE_HELP: &str = "\
Scene file (TOML) holding any of the render settings, so that a render can be
shared and reproduced. Precedence: a flag given on the command line, then the
scene's value, then the flag's default. Each flag replaces the scene key of the
same name (--light replaces all [[lights]]; a VOLUME replaces the scene's volume
and its raw layout). Relative paths in the scene (volume.path, output.path,
turntable.path, profile:@FILE) are relative to the scene file's directory.

  [volume]     path = \"head.nii.gz\" | builtin = \"teapot@128\", raw_dims = [X, Y, Z],
               raw_type, raw_endian, background, resample
  [camera]     dir = [X, Y, Z], up = [X, Y, Z], size = N | [W, H]
  [spectrum]   filter, oversample, precision, kb_design, accuracy
  [shading]    ambient = G | [R, G, B], depth_cue = \"linear:1,0.3\", cue_harmonics,
               cue_correction = true
  [light_ring] count, tilt
  [[lights]]   direction = [X, Y, Z], color = G | [R, G, B]      (repeatable)
  [output]     path, bits = 8 | 16, window, level, percentiles = [LO, HI], colormap
  [turntable]  frames, fps, path                                (turntable only)

Unknown keys and wrong types are errors naming the file, the key and the closest
valid key. Examples: the examples/ directory of the repository.";

/// A subcommand whose settings a scene file can fill.
pub(crate) trait FromScene {
    /// The `--scene` file given, if any.
    fn scene_file(&self) -> Option<&Path>;
    /// Fill the settings the command line did not give (`given`) from `scene`.
    fn apply_scene(&mut self, scene: &SceneFile, given: &dyn Fn(&str) -> bool);
}

impl FromScene for RenderArgs {
    fn scene_file(&self) -> Option<&Path> {
        self.scene.as_deref()
    }

    fn apply_scene(&mut self, scene: &SceneFile, given: &dyn Fn(&str) -> bool) {
        apply_scene_to_render(self, scene, given);
    }
}

impl FromScene for TurntableArgs {
    fn scene_file(&self) -> Option<&Path> {
        self.scene.as_deref()
    }

    fn apply_scene(&mut self, scene: &SceneFile, given: &dyn Fn(&str) -> bool) {
        apply_scene_to_turntable(self, scene, given);
    }
}

/// Load the `--scene` file of `args`, if any, and fill `args` from it.
pub(crate) fn merge_scene(
    args: &mut impl FromScene,
    given: &dyn Fn(&str) -> bool,
) -> Result<(), Error> {
    let Some(path) = args.scene_file().map(Path::to_path_buf) else {
        return Ok(());
    };
    let scene = SceneFile::load(&path)?;
    args.apply_scene(&scene, given);
    Ok(())
}
