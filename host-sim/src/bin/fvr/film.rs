//! `--display film`: the PNG of an X-ray render as a radiograph shows it
//! ([`fvr_host::image::film`]).

use fvr_host::image::film::{apply_film, film_gain, Display};
use fvr_host::image::AUTO_WINDOW_PERCENTILES;

use crate::args::PngArgs;
use crate::Error;

/// The pixels a film PNG writes and their window.
pub(crate) type FilmPng = (Vec<f64>, (f64, f64));

/// The pixels to write and their window for `--display film` (`None` for
/// `linear`): `1 − exp(−k·p)` on `[0, 1]`, or through the window the user
/// gave. Refused for colour images, whose channels are not line integrals.
pub(crate) fn film_png(
    png: &PngArgs,
    data: &[f64],
    channels: usize,
) -> Result<Option<FilmPng>, Error> {
    let Display::Film(k) = png.display else {
        return Ok(None);
    };
    if channels != 1 {
        return Err(
            "--display film shows the line integrals of a grey X-ray render; \
                    lights make a colour image: drop --light/--light-ring or --display film"
                .into(),
        );
    }
    let Some(k) = k.or_else(|| film_gain(data)) else {
        return Err(
            "--display film: the image has no positive line integral to scale \
                    (an empty view?): give film:K"
                .into(),
        );
    };
    let mut shown = data.to_vec();
    apply_film(&mut shown, k);
    let explicit = png.window.is_some() || png.percentiles != AUTO_WINDOW_PERCENTILES;
    let range = if explicit {
        png.style()?.window.resolve(&shown)
    } else {
        (0.0, 1.0)
    };
    Ok(Some((shown, range)))
}
