//! `--taper[=VOXELS]`: fade the content the volume's box cuts (a CT head's
//! neck) to zero before preparing it, so that the cut does not ring in the
//! projection (`fvr_engine::volume::taper`; docs/cli.md, "Cut volumes").

use clap::Args;
use fvr_engine::volume::taper::{taper_cut_faces, DEFAULT_TAPER_VOXELS};
use fvr_engine::volume::Volume;
use serde::Serialize;

use crate::Error;

/// The taper option, one group for every subcommand that prepares a volume.
#[derive(Args, Clone, Default)]
pub(crate) struct TaperArgs {
    /// Fade content cut by the volume's box (a CT head's neck) to zero over
    /// VOXELS voxels (8 if no number is given) with a raised cosine, so that
    /// the cut face does not ring in the projection. Only faces that cut
    /// content are tapered, and those voxels change: the image is of the
    /// tapered volume (docs/cli.md, "Cut volumes").
    #[arg(
        long,
        value_name = "VOXELS",
        num_args = 0..=1,
        default_missing_value = DEFAULT_TAPER_VOXELS_STR,
    )]
    pub(crate) taper: Option<usize>,
}

const DEFAULT_TAPER_VOXELS_STR: &str = "8";
const _: () = assert!(DEFAULT_TAPER_VOXELS == 8);

/// What `--stats-json` says of the taper (`null` without one).
#[derive(Clone, Serialize)]
pub(crate) struct TaperJson {
    /// Voxels faded over.
    pub(crate) voxels: usize,
    /// The faces tapered (`i-`, `i+`, `j-`, `j+`, `k-`, `k+`); empty when
    /// no face cut content.
    pub(crate) faces: Vec<&'static str>,
}

impl TaperArgs {
    /// Refuse `--taper 0` before any work.
    pub(crate) fn check(&self) -> Result<(), Error> {
        if self.taper == Some(0) {
            return Err("--taper 0: give the width of the taper in voxels, 1 or more".into());
        }
        Ok(())
    }

    /// Taper `volume` when asked, saying on stderr which faces (unless
    /// quiet).
    pub(crate) fn apply(&self, volume: &mut Volume) -> Result<Option<TaperJson>, Error> {
        let Some(voxels) = self.taper else {
            return Ok(None);
        };
        let faces = taper_cut_faces(volume, voxels)?;
        if !fvr_host::progress::quiet() {
            if faces.none() {
                eprintln!(
                    "fvr: note: --taper: no face of the volume cuts content; nothing tapered"
                );
            } else {
                eprintln!(
                    "fvr: note: --taper: faded the content at face{} {} over {voxels} voxels",
                    if faces.names().len() > 1 { "s" } else { "" },
                    faces.names().join(", ")
                );
            }
        }
        Ok(Some(TaperJson {
            voxels,
            faces: faces.names(),
        }))
    }
}
