//! Volumes by name: files on disk, named data sets or built-in phantoms.

pub mod datasets;
pub use fvr_engine::volume::phantom;
pub mod teapot;

use std::path::Path;

use indicatif::ProgressBar;

use crate::io::nrrd::{read_raw, Endian, SampleType};
use crate::io::{read_volume_with_progress, FORMATS_HELP};
use crate::sources::datasets::{load_dataset_with_progress, DATASETS_HELP};
use crate::sources::teapot::{voxelize_teapot, DEFAULT_TEAPOT_SIZE};
use fvr_engine::volume::phantom::{sample, GaussianMixture, Phantom, SheppLogan, Sphere};
use fvr_engine::volume::Volume;

/// Default side of built-in phantoms.
pub const DEFAULT_PHANTOM_SIZE: usize = 64;
/// Largest side accepted for a built-in phantom.
pub const MAX_PHANTOM_SIZE: usize = 1024;
/// Seed of the `gaussians` phantom unless one is given.
pub const DEFAULT_SEED: u64 = 1;
/// Components of the `gaussians` phantom.
pub const GAUSSIAN_COUNT: usize = 8;
/// Components of the `blobs` phantom.
pub const BLOB_COUNT: usize = 24;
/// Largest σ of the `blobs` phantom, as a fraction of its side.
pub const BLOB_SIGMA_FRACTION: f64 = 0.05;

/// The built-in phantoms, as `name[@SIZE][:SEED]`.
pub const PHANTOM_HELP: &str = "built-in phantoms: `gaussians[@N][:SEED]` (8 random anisotropic \
Gaussians, sigma 1.5 to 0.12 N voxels, inside the sphere of radius 0.4 N), `blobs[@N][:SEED]` (24 \
smaller ones, sigma 1.5 to 0.05 N), `shepp-logan[@N]` (modified 3D \
Shepp-Logan), `sphere[@N]` (uniform ball of radius 0.3 N); N defaults to 64; and \
`teapot[@N]` (Newell's Utah teapot voxelized from its 32 Bezier patches, N defaults to 128)";

/// A phantom with its sampled volume.
pub struct PhantomVolume {
    /// The analytic phantom (for exact references).
    pub phantom: Box<dyn Phantom>,
    /// Its samples.
    pub volume: Volume,
}

/// Parse `name[@N][:SEED]` into a built-in phantom, or `None` if `spec` names
/// no phantom.
///
/// # Errors
/// A known name with a malformed size or seed.
pub fn phantom_by_name(spec: &str) -> Option<Result<PhantomVolume, String>> {
    let (head, seed) = match spec.split_once(':') {
        Some((h, s)) => (h, Some(s)),
        None => (spec, None),
    };
    let (name, size) = match head.split_once('@') {
        Some((n, s)) => (n, Some(s)),
        None => (head, None),
    };
    if !["gaussians", "blobs", "shepp-logan", "sphere"].contains(&name) {
        return None;
    }
    Some(build_phantom(name, size, seed))
}

fn build_phantom(
    name: &str,
    size: Option<&str>,
    seed: Option<&str>,
) -> Result<PhantomVolume, String> {
    let n = match size {
        None => DEFAULT_PHANTOM_SIZE,
        Some(s) => s
            .parse::<usize>()
            .ok()
            .filter(|&n| (4..=MAX_PHANTOM_SIZE).contains(&n))
            .ok_or_else(|| {
                format!("phantom size `{s}` must be an integer from 4 to {MAX_PHANTOM_SIZE}")
            })?,
    };
    let seed = match seed {
        None => DEFAULT_SEED,
        Some(s) if name == "gaussians" || name == "blobs" => s
            .parse::<u64>()
            .map_err(|_| format!("phantom seed `{s}` must be a non-negative integer"))?,
        Some(_) => return Err(format!("phantom `{name}` takes no seed")),
    };
    let dims = [n, n, n];
    crate::budget::check_load(dims, 0).map_err(|e| e.to_string())?;
    let phantom: Box<dyn Phantom> = match name {
        "gaussians" => Box::new(GaussianMixture::random(seed, n, GAUSSIAN_COUNT)),
        "blobs" => Box::new(GaussianMixture::random_with(
            seed,
            n,
            BLOB_COUNT,
            BLOB_SIGMA_FRACTION,
        )),
        "shepp-logan" => Box::new(SheppLogan::new(dims)),
        _ => Box::new(Sphere {
            center: dims.map(|d| d as f64 / 2.0),
            radius: 0.3 * n as f64,
            density: 1.0,
        }),
    };
    let volume = sample(phantom.as_ref(), dims);
    Ok(PhantomVolume { phantom, volume })
}

/// Parse `teapot[@N]` into the voxelized Utah teapot ([`crate::sources::teapot`]),
/// or `None` if `spec` names something else.
///
/// # Errors
/// A malformed or out-of-range size.
pub fn teapot_by_name(spec: &str) -> Option<Result<Volume, String>> {
    let size = match spec.strip_prefix("teapot")? {
        "" => Ok(DEFAULT_TEAPOT_SIZE),
        rest => match rest.strip_prefix('@') {
            Some(n) => n.parse::<usize>().map_err(|_| {
                format!("teapot size `{n}` must be an integer from 8 to {MAX_PHANTOM_SIZE}")
            }),
            None if rest.starts_with(':') => Err("phantom `teapot` takes no seed".to_string()),
            None => return None,
        },
    };
    Some(size.and_then(|n| {
        // Voxelizing holds three f64 grids (coverage, smoothing) besides the volume.
        let count = (n as u64).saturating_pow(3);
        crate::budget::check_load([n; 3], count.saturating_mul(24)).map_err(|e| e.to_string())?;
        voxelize_teapot(n).map(|t| t.volume)
    }))
}

/// Layout of a headerless raw file.
#[derive(Clone, Copy, Debug)]
pub struct RawLayout {
    /// Sizes.
    pub dims: [usize; 3],
    /// Sample type.
    pub ty: SampleType,
    /// Byte order.
    pub endian: Endian,
}

/// Load a volume: a built-in phantom (`gaussians@64`), a named data set
/// (`brainsmall`, `ct-head`: [`crate::sources::datasets`]), a raw file when `raw` is
/// given, or a volume file of any format [`crate::io`] reads.
///
/// # Errors
/// Unknown names, missing data sets, unreadable or malformed files, with
/// the file and the field at fault.
pub fn load_volume(spec: &str, raw: Option<RawLayout>) -> Result<Volume, String> {
    load_volume_with_progress(spec, raw, &ProgressBar::hidden())
}

/// The files loading `spec` will read, as far as they are known before
/// loading: the file itself and the data file of a detached NRRD header,
/// or the file a data set's environment variable names (`FVR_CT_HEAD`,
/// `FVR_MRI_HEAD`). Phantoms read none. For checking outputs before any
/// work; the job's inputs are recorded again as they are opened
/// ([`crate::io::inputs`]).
pub fn input_files(spec: &str) -> Vec<std::path::PathBuf> {
    let path = Path::new(spec);
    if path.is_file() {
        let mut files = vec![path.to_path_buf()];
        files.extend(crate::io::nrrd::detached_data_file(path));
        return files;
    }
    let dataset = match spec {
        "ct-head" => crate::sources::datasets::ct_head_path(),
        "mri-head" => crate::sources::datasets::mri_head_path(),
        _ => return Vec::new(),
    };
    let Ok(file) = dataset else {
        return Vec::new();
    };
    let mut files = vec![file.clone()];
    files.extend(crate::io::nrrd::detached_data_file(&file));
    files
}

/// [`load_volume`], advancing `progress` by the bytes read from disk.
///
/// # Errors
/// As [`load_volume`].
pub fn load_volume_with_progress(
    spec: &str,
    raw: Option<RawLayout>,
    progress: &ProgressBar,
) -> Result<Volume, String> {
    if let Some(p) = phantom_by_name(spec) {
        return p.map(|p| p.volume);
    }
    if let Some(t) = teapot_by_name(spec) {
        return t;
    }
    let path = Path::new(spec);
    if let Some(r) = raw {
        return read_raw(path, r.dims, r.ty, r.endian).map_err(|e| e.to_string());
    }
    if !path.exists() {
        if let Some(v) = load_dataset_with_progress(spec, progress) {
            return v;
        }
        return Err(no_such_volume(spec));
    }
    read_volume_with_progress(path, progress).map_err(|e| e.to_string())
}

/// The names `VOLUME` may take besides a file (without `@N` or `:SEED`).
const BUILT_IN_NAMES: &[&str] = &[
    "gaussians",
    "blobs",
    "shepp-logan",
    "sphere",
    "teapot",
    "brainsmall",
    "ct-head",
    "mri-head",
];

/// The one-line message for a `VOLUME` that is neither a file nor a known
/// name: the nearest directory entry or built-in name when one is close,
/// else the formats, data sets and phantoms it could be.
fn no_such_volume(spec: &str) -> String {
    match nearest_volume_name(spec) {
        Some(near) => format!("no such file or volume `{spec}`; did you mean `{near}`?"),
        None => format!(
            "no such file or volume `{spec}`: neither a file nor a built-in phantom, and no data \
             set has that name; files can be {FORMATS_HELP}; {DATASETS_HELP}; {PHANTOM_HELP}"
        ),
    }
}

/// How close `candidate` is to `name` (lower is closer), or `None` when it
/// is not close: an edit distance of at most 3 (and less than half the
/// name), or one name a prefix or suffix of the other (`mni152.nii` and
/// `mni152.nii.gz`).
fn closeness(name: &str, candidate: &str) -> Option<usize> {
    if name == candidate || name.is_empty() {
        return None;
    }
    let d = crate::scene_file::edit_distance(name, candidate);
    let len = name.chars().count().min(candidate.chars().count());
    let affix = len >= 4
        && (candidate.starts_with(name)
            || name.starts_with(candidate)
            || candidate.ends_with(name)
            || name.ends_with(candidate));
    (d <= 3 && 2 * d < len.max(1) + 1 || affix).then_some(d)
}

/// The nearest name to `spec`: among the entries of its directory (at most
/// 10,000 read) and the built-in names (keeping `@N` or `:SEED`).
fn nearest_volume_name(spec: &str) -> Option<String> {
    let mut best: Option<(usize, String)> = None;
    let mut offer = |d: usize, s: String| {
        if best.as_ref().is_none_or(|(b, _)| d < *b) {
            best = Some((d, s));
        }
    };
    let cut = spec.find(['@', ':']).unwrap_or(spec.len());
    let (head, tail) = spec.split_at(cut);
    for name in BUILT_IN_NAMES {
        if let Some(d) = closeness(head, name) {
            offer(d, format!("{name}{tail}"));
        }
    }
    let path = Path::new(spec);
    if let Some(file) = path.file_name().and_then(|f| f.to_str()) {
        let parent = path.parent().filter(|p| !p.as_os_str().is_empty());
        let dir = parent.unwrap_or(Path::new("."));
        if let Ok(entries) = std::fs::read_dir(dir) {
            for entry in entries.flatten().take(10_000) {
                let Ok(entry_name) = entry.file_name().into_string() else {
                    continue;
                };
                if let Some(d) = closeness(file, &entry_name) {
                    let shown = match parent {
                        Some(p) => p.join(&entry_name).display().to_string(),
                        None => entry_name,
                    };
                    offer(d, shown);
                }
            }
        }
    }
    best.map(|(_, s)| crate::text::bounded(&s))
}
