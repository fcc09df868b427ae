//! Images are finite or refused. Every image leaves the engine as `f32`
//! (NRRD, `.npy`, NumPy arrays), and a render whose values overflow it
//! (a volume near `f32::MAX`, an ambient, light or cue weight of `1e300`)
//! is an error naming what to lower, never a NaN or infinite image.

use fvr_core::shading::{DepthCue, Scene};

use crate::error::PipelineError;

/// The names a front end gives the settings [`overflow_cause`] may blame.
#[derive(Clone, Copy, Debug)]
pub struct SettingNames<'a> {
    /// The ambient colour.
    pub ambient: &'a str,
    /// The lights' colours.
    pub lights: &'a str,
    /// The depth cue's weights.
    pub depth_cue: &'a str,
    /// What to do when no setting was given and the volume overflowed.
    pub volume: &'a str,
}

/// The engine's own names (the Python package's messages).
pub const ENGINE_NAMES: SettingNames<'static> = SettingNames {
    ambient: "the ambient colour",
    lights: "the light colours",
    depth_cue: "the depth-cue weights",
    volume: "the volume's values (times its voxel size in mm) are too large; rescale the volume",
};

/// Which of ambient, lights and depth cue `scene` was given (an ambient
/// other than [`Scene::default_ambient`], any light, any cue).
pub fn given(scene: &Scene) -> [bool; 3] {
    [
        scene.ambient != [Scene::default_ambient(!scene.lights.is_empty()); 3],
        !scene.lights.is_empty(),
        scene.cue != DepthCue::None,
    ]
}

/// What to lower when an image overflows: the shading settings given
/// (`[ambient, lights, depth cue]`, [`given`]) by their `names`, or else
/// the volume itself. Settings left at their defaults are not named.
pub fn overflow_cause(given: [bool; 3], names: &SettingNames<'_>) -> String {
    let named: Vec<&str> = given
        .iter()
        .zip([names.ambient, names.lights, names.depth_cue])
        .filter(|(g, _)| **g)
        .map(|(_, name)| name)
        .collect();
    match named.as_slice() {
        [] => names.volume.to_string(),
        [one] => format!("a setting overflowed; lower {one}"),
        [a, b] => format!("a setting overflowed; lower {a} or {b}"),
        _ => format!("a setting overflowed; lower {}", named.join(", ")),
    }
}

/// `Ok` when every value of the frames in `out` (each `frame` values long)
/// is finite, else [`PipelineError::Overflow`] naming the first frame
/// with a non-finite value and what to lower ([`overflow_cause`]).
///
/// # Errors
/// A NaN or infinite value.
pub fn check_frames(out: &[f32], frame: usize, scene: &Scene) -> Result<(), PipelineError> {
    match out.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(PipelineError::Overflow {
            view: i / frame.max(1),
            value: out[i],
            cause: overflow_cause(given(scene), &ENGINE_NAMES),
        }),
    }
}

/// [`check_frames`] for one image held in `f64` ([`crate::Renderer::render`]):
/// `Ok` when every value is finite once narrowed to `f32`, as every output
/// stores it.
///
/// # Errors
/// A value that is NaN or infinite in `f32`, as [`PipelineError::Overflow`]
/// of view 0.
pub fn check_image(data: &[f64], scene: &Scene) -> Result<(), PipelineError> {
    match data.iter().position(|&v| !(v as f32).is_finite()) {
        None => Ok(()),
        Some(i) => Err(PipelineError::Overflow {
            view: 0,
            value: data[i] as f32,
            cause: overflow_cause(given(scene), &ENGINE_NAMES),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use fvr_core::shading::Light;

    #[test]
    fn only_settings_given_are_blamed() {
        let cause = |scene: &Scene| overflow_cause(given(scene), &ENGINE_NAMES);
        let mut scene = Scene::xray();
        assert!(cause(&scene).contains("rescale the volume"));
        scene.ambient = [2.0; 3];
        assert_eq!(
            cause(&scene),
            "a setting overflowed; lower the ambient colour"
        );
        scene
            .add_light(Light {
                towards: [1.0, 0.0, 0.0],
                color: [1.0; 3],
            })
            .unwrap();
        assert!(cause(&scene).ends_with("the ambient colour or the light colours"));
        // With lights, the default ambient is 0.2, and not blamed.
        scene.ambient = [Scene::default_ambient(true); 3];
        assert_eq!(
            cause(&scene),
            "a setting overflowed; lower the light colours"
        );
    }

    #[test]
    fn the_first_bad_value_is_named_by_view_and_pixel() {
        let scene = Scene::xray();
        assert!(check_frames(&[1.0; 8], 4, &scene).is_ok());
        let mut out = [1.0f32; 8];
        out[6] = f32::INFINITY;
        let e = check_frames(&out, 4, &scene).unwrap_err().to_string();
        assert!(e.starts_with("view 1 has non-finite pixels"), "{e}");
        assert!(e.contains("(the first is inf): "), "{e}");
        out[6] = f32::NAN;
        assert!(check_frames(&out, 4, &scene).is_err());
    }

    #[test]
    fn an_image_that_overflows_f32_is_refused() {
        let scene = Scene::xray();
        assert!(check_image(&[1.0, f64::from(f32::MAX)], &scene).is_ok());
        // Finite in f64, infinite once stored as f32.
        let e = check_image(&[1.0, 1e39], &scene).unwrap_err();
        assert!(matches!(e, PipelineError::Overflow { view: 0, .. }), "{e}");
        assert!(check_image(&[f64::NAN], &scene).is_err());
    }
}
