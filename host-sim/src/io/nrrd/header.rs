//! Reading and validating a NRRD header (attached, or detached in a `.nhdr`).

use std::io::{BufRead, Read};

use super::error::{excerpt, field_error, header_error, IoError};
use super::samples::{Encoding, Endian, SampleType};

/// Longest header line accepted, in bytes (newline included).
const MAX_LINE_BYTES: usize = 1 << 20;
/// Longest header accepted, in bytes.
const MAX_HEADER_BYTES: usize = 16 << 20;

/// Everything needed to decode the data that follows a header.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Layout {
    /// Volume dimensions, padded with 1s.
    pub(crate) dims: [usize; 3],
    /// Number of samples.
    pub count: usize,
    /// Bytes of sample data (`count` times the sample size).
    pub data_bytes: usize,
    /// Sample type.
    pub ty: SampleType,
    /// Byte order (`Little` for 1-byte types, where it does not matter).
    pub endian: Endian,
    /// Data encoding.
    pub encoding: Encoding,
    /// Lines to skip before the data (in the file, before decompression).
    pub line_skip: u64,
    /// Bytes to skip before the data (after decompression for gzip).
    pub byte_skip: u64,
    /// Voxel spacing from `spacings` or the lengths of `space directions`
    /// (1 for axes without one).
    pub spacing: [f64; 3],
    /// The `data file` field: the data is in this file, relative to the
    /// header's directory, not after the header.
    pub data_file: Option<String>,
    /// The axes and origin in the patient (RAS), from a patient `space`,
    /// three `space directions` vectors and `space origin`.
    pub orientation: Option<fvr_engine::volume::Orientation>,
    /// `kinds: RGB-color domain domain` (or `space`): a colour image, which
    /// only the image reader accepts ([`Layout::check_volume`]).
    pub colour: bool,
    /// `kinds: space space list` (or `domain`): a stack of images, one per
    /// view, as `fvr project` writes it; also only for the image reader.
    pub stack: bool,
}

impl Layout {
    /// The layout of `count` bare samples of `ty` (no skips, raw encoding,
    /// unit spacing), `dims` padded to 3 with `count` their product.
    pub(crate) fn samples(
        dims: [usize; 3],
        count: usize,
        data_bytes: usize,
        ty: SampleType,
        endian: Endian,
    ) -> Self {
        Layout {
            dims,
            count,
            data_bytes,
            ty,
            endian,
            encoding: Encoding::Raw,
            line_skip: 0,
            byte_skip: 0,
            spacing: fvr_engine::volume::DEFAULT_SPACING,
            data_file: None,
            orientation: None,
            colour: false,
            stack: false,
        }
    }

    /// `Ok` unless this is a colour image or a stack: a volume's axes must
    /// all be spatial.
    ///
    /// # Errors
    /// The `kinds` error naming the colour or list axis.
    pub(crate) fn check_volume(&self) -> Result<(), IoError> {
        let axis = match (self.colour, self.stack) {
            (true, _) => "axis 0 is `RGB-color`",
            (_, true) => "axis 2 is `list`",
            _ => return Ok(()),
        };
        Err(field_error(
            "kinds",
            format!("{axis}: only scalar volumes with spatial axes can be rendered"),
        ))
    }
}

/// The raw values of the fields this reader cares about.
#[derive(Debug, Default)]
struct Fields {
    ty: Option<String>,
    dimension: Option<String>,
    sizes: Option<String>,
    encoding: Option<String>,
    endian: Option<String>,
    byte_skip: Option<String>,
    line_skip: Option<String>,
    data_file: Option<String>,
    spacings: Option<String>,
    space_directions: Option<String>,
    kinds: Option<String>,
    space: Option<String>,
    space_origin: Option<String>,
}

impl Fields {
    /// The canonical name and storage slot of a field, `None` for fields
    /// that are accepted and ignored.
    fn slot(&mut self, key: &str) -> Option<(&'static str, &mut Option<String>)> {
        Some(match key {
            "type" => ("type", &mut self.ty),
            "dimension" => ("dimension", &mut self.dimension),
            "sizes" => ("sizes", &mut self.sizes),
            "encoding" => ("encoding", &mut self.encoding),
            "endian" => ("endian", &mut self.endian),
            "byte skip" | "byteskip" => ("byte skip", &mut self.byte_skip),
            "line skip" | "lineskip" => ("line skip", &mut self.line_skip),
            "data file" | "datafile" => ("data file", &mut self.data_file),
            "spacings" => ("spacings", &mut self.spacings),
            "space directions" => ("space directions", &mut self.space_directions),
            "kinds" => ("kinds", &mut self.kinds),
            "space" => ("space", &mut self.space),
            "space origin" => ("space origin", &mut self.space_origin),
            _ => return None,
        })
    }

    /// Record `key: value`; duplicates of known fields are an error.
    fn set(&mut self, key: &str, value: &str) -> Result<(), IoError> {
        let key = key
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
            .to_ascii_lowercase();
        match self.slot(&key) {
            Some((name, slot)) if slot.is_some() => Err(field_error(name, "given more than once")),
            Some((_, slot)) => {
                *slot = Some(value.to_owned());
                Ok(())
            }
            None => Ok(()),
        }
    }

    /// Check and convert the fields.
    fn into_layout(self) -> Result<Layout, IoError> {
        let ty = SampleType::from_nrrd_field(&required(self.ty, "type")?)?;
        let dimension = parse_dimension(&required(self.dimension, "dimension")?)?;
        let sizes = parse_sizes(&required(self.sizes, "sizes")?, dimension)?;
        let encoding = Encoding::from_nrrd_field(&required(self.encoding, "encoding")?)?;
        let endian = match ty.size_bytes() {
            1 => Endian::Little,
            _ => Endian::from_nrrd_field(&required(self.endian, "endian")?)?,
        };
        let byte_skip = parse_skip(self.byte_skip.as_deref(), "byte skip")?;
        let line_skip = parse_skip(self.line_skip.as_deref(), "line skip")?;
        let (dims, count, data_bytes) = geometry(&sizes, ty)?;
        let kinds = match &self.kinds {
            Some(kinds) => check_kinds(kinds)?,
            None => Kinds::Space,
        };
        let (colour, stack) = (kinds == Kinds::Colour, kinds == Kinds::Stack);
        let mut vectors = Vec::new();
        let spacing = match (self.spacings, self.space_directions) {
            // The format forbids both; `space directions` is the fuller one.
            (_, Some(d)) => {
                let (spacing, v) = parse_space_directions(&d, dimension)?;
                vectors = v;
                spacing
            }
            (Some(s), None) => parse_spacings(&s, dimension, kinds.unspaced_axis())?,
            (None, None) => fvr_engine::volume::DEFAULT_SPACING,
        };
        let orientation = super::space::orientation(
            self.space.as_deref(),
            &vectors,
            self.space_origin.as_deref(),
        )?;
        let data_file = match self.data_file {
            Some(f) => Some(parse_data_file(&f)?),
            None => None,
        };
        Ok(Layout {
            dims,
            count,
            data_bytes,
            ty,
            endian,
            encoding,
            line_skip,
            byte_skip,
            spacing,
            data_file,
            orientation,
            colour,
            stack,
        })
    }
}

fn required(value: Option<String>, field: &'static str) -> Result<String, IoError> {
    value.ok_or(IoError::MissingField { field })
}

fn parse_dimension(value: &str) -> Result<usize, IoError> {
    match value.trim().parse::<usize>() {
        Ok(d @ 1..=3) => Ok(d),
        Ok(0) => Err(field_error("dimension", "must be at least 1, got `0`")),
        Ok(d) => Err(field_error(
            "dimension",
            format!("dimension {d} is not supported (at most 3)"),
        )),
        Err(_) => Err(field_error(
            "dimension",
            format!("expected a positive integer, got `{}`", excerpt(value)),
        )),
    }
}

fn parse_sizes(value: &str, dimension: usize) -> Result<Vec<usize>, IoError> {
    let sizes: Option<Vec<usize>> = value
        .split_whitespace()
        .map(|s| s.parse::<usize>().ok().filter(|&n| n > 0))
        .collect();
    match sizes {
        Some(sizes) if sizes.len() == dimension => Ok(sizes),
        _ => Err(field_error(
            "sizes",
            format!(
                "expected {dimension} positive integer{}, got `{}`",
                if dimension == 1 { "" } else { "s" },
                excerpt(value.trim())
            ),
        )),
    }
}

/// The `spacings` field: one finite positive number per axis (`nan` on
/// the axis `unspaced`, a colour or list axis, which has none).
fn parse_spacings(
    value: &str,
    dimension: usize,
    unspaced: Option<usize>,
) -> Result<[f64; 3], IoError> {
    let words: Vec<&str> = value.split_whitespace().collect();
    if words.len() != dimension {
        return Err(field_error(
            "spacings",
            format!(
                "expected {dimension} number{}, got `{}`",
                if dimension == 1 { "" } else { "s" },
                excerpt(value.trim())
            ),
        ));
    }
    let mut spacing = fvr_engine::volume::DEFAULT_SPACING;
    for (axis, (slot, word)) in spacing.iter_mut().zip(&words).enumerate() {
        // A colour or list axis has no spacing.
        if unspaced == Some(axis) && word.eq_ignore_ascii_case("nan") {
            continue;
        }
        *slot = word
            .parse::<f64>()
            .map_err(|_| field_error("spacings", format!("`{}` is not a number", excerpt(word))))?;
    }
    fvr_engine::volume::check_spacing(spacing).map_err(|e| field_error("spacings", e.to_string()))
}

/// The `space directions` field: per axis a vector `(x,y,z)` (or `none`);
/// the spacing is its length. Only the lengths are kept: rendering happens
/// in index space, scaled per axis.
fn parse_space_directions(
    value: &str,
    dimension: usize,
) -> Result<([f64; 3], Vec<[f64; 3]>), IoError> {
    let bad = |why: String| field_error("space directions", why);
    let mut spacing = fvr_engine::volume::DEFAULT_SPACING;
    let mut units: Vec<[f64; 3]> = Vec::new();
    let mut vectors: Vec<[f64; 3]> = Vec::new();
    let mut rest = value.trim();
    let mut axis = 0;
    while !rest.is_empty() {
        if axis == dimension {
            return Err(bad(format!(
                "more than {dimension} vectors in `{}`",
                excerpt(value.trim())
            )));
        }
        if let Some(after) = rest.strip_prefix("none") {
            rest = after.trim_start();
            axis += 1;
            // An axis without a vector: no orientation.
            vectors.push([f64::NAN; 3]);
            continue;
        }
        let inner = rest
            .strip_prefix('(')
            .and_then(|r| r.split_once(')'))
            .ok_or_else(|| {
                bad(format!(
                    "expected vectors `(x,y,z)` or `none`, got `{}`",
                    excerpt(rest)
                ))
            })?;
        let components: Option<Vec<f64>> = inner
            .0
            .split(',')
            .map(|c| c.trim().parse::<f64>().ok())
            .collect();
        let components = components.filter(|c| !c.is_empty()).ok_or_else(|| {
            bad(format!(
                "vector `({})` of axis {axis} is not a list of numbers",
                excerpt(inner.0)
            ))
        })?;
        let length = components.iter().map(|c| c * c).sum::<f64>().sqrt();
        if !(length.is_finite() && length > 0.0) {
            return Err(bad(format!(
                "vector `({})` of axis {axis} has length {length}; it must be finite and non-zero",
                excerpt(inner.0)
            )));
        }
        spacing[axis] = length;
        if let [x, y, z] = components[..] {
            units.push([x / length, y / length, z / length]);
            vectors.push([x, y, z]);
        }
        rest = inner.1.trim_start();
        axis += 1;
    }
    if !crate::io::spans_independent_axes(&units) {
        return Err(bad(format!(
            "the vectors of `{}` are parallel or nearly so: the grid would have no volume",
            excerpt(value.trim())
        )));
    }
    if axis != dimension {
        return Err(bad(format!(
            "expected {dimension} vectors (or `none`), got {axis}"
        )));
    }
    if vectors.len() != 3 || vectors.iter().flatten().any(|c| !c.is_finite()) {
        vectors.clear();
    }
    Ok((spacing, vectors))
}

/// What the `kinds` field says the axes are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kinds {
    /// Every axis spatial (or unknown).
    Space,
    /// `RGB-color` then two spatial axes.
    Colour,
    /// Two spatial axes then a `list`: a stack of images.
    Stack,
}

impl Kinds {
    /// The axis without a spacing.
    fn unspaced_axis(self) -> Option<usize> {
        match self {
            Kinds::Space => None,
            Kinds::Colour => Some(0),
            Kinds::Stack => Some(2),
        }
    }
}

/// The `kinds` field: every axis must be a spatial one (`domain`, `space`,
/// or unknown: `none`, `???`). A colour, vector or list axis would be
/// rendered as space.
///
/// A colour image (`RGB-color` then two spatial axes) and a stack of
/// images (two spatial axes then `list`) are told apart: only the image
/// reader accepts them.
fn check_kinds(value: &str) -> Result<Kinds, IoError> {
    let words: Vec<&str> = value.split_whitespace().collect();
    let spatial = |k: &str| matches!(k, "domain" | "space" | "none" | "???");
    match words[..] {
        ["RGB-color", a, b] if spatial(a) && spatial(b) => return Ok(Kinds::Colour),
        [a, b, "list"] if spatial(a) && spatial(b) => return Ok(Kinds::Stack),
        _ => {}
    }
    for (axis, kind) in value.split_whitespace().enumerate() {
        if !matches!(kind, "domain" | "space" | "none" | "???") {
            return Err(field_error(
                "kinds",
                format!(
                    "axis {axis} is `{}`: only scalar volumes with spatial axes can be rendered",
                    excerpt(kind)
                ),
            ));
        }
    }
    Ok(Kinds::Space)
}

/// The `data file` field: a single file name. The multi-file forms
/// (`LIST`, or a format string with min, max and step) are refused.
fn parse_data_file(value: &str) -> Result<String, IoError> {
    let name = value.trim();
    if name.is_empty() {
        return Err(field_error("data file", "is empty"));
    }
    if name == "LIST" || name.starts_with("LIST ") || name.split_whitespace().count() > 1 {
        return Err(field_error(
            "data file",
            format!(
                "`{}` names several data files; only a single detached data file is supported",
                excerpt(name)
            ),
        ));
    }
    Ok(name.to_owned())
}

fn parse_skip(value: Option<&str>, field: &'static str) -> Result<u64, IoError> {
    let Some(value) = value else { return Ok(0) };
    match value.trim().parse::<i64>() {
        Ok(n) if n >= 0 => Ok(n as u64),
        Ok(-1) => Err(field_error(
            field,
            "-1 (data at the end of the file) is not supported; give a nonnegative count",
        )),
        _ => Err(field_error(
            field,
            format!("expected a nonnegative integer, got `{}`", excerpt(value)),
        )),
    }
}

/// Dimensions padded to 3, sample count and data bytes, with overflow checks.
pub(crate) fn geometry(
    sizes: &[usize],
    ty: SampleType,
) -> Result<([usize; 3], usize, usize), IoError> {
    let overflow = || field_error("sizes", format!("product of sizes {sizes:?} overflows"));
    let count = sizes
        .iter()
        .try_fold(1usize, |acc, &n| acc.checked_mul(n))
        .ok_or_else(overflow)?;
    let data_bytes = count.checked_mul(ty.size_bytes()).ok_or_else(overflow)?;
    let mut dims = [1usize; 3];
    for (d, &n) in dims.iter_mut().zip(sizes) {
        *d = n;
    }
    Ok((dims, count, data_bytes))
}

/// Reads header lines, enforcing the per-line and total length limits.
struct LineReader<'a, R> {
    reader: &'a mut R,
    buf: Vec<u8>,
    line: usize,
    total: usize,
}

impl<R: BufRead> LineReader<'_, R> {
    /// The next line without its `\n` or `\r\n`, `None` at end of input.
    fn next_line(&mut self) -> Result<Option<String>, IoError> {
        self.buf.clear();
        self.line += 1;
        let limit = MAX_LINE_BYTES as u64 + 1;
        let n = self
            .reader
            .by_ref()
            .take(limit)
            .read_until(b'\n', &mut self.buf)?;
        if n == 0 {
            return Ok(None);
        }
        self.total = self.total.saturating_add(n);
        if n > MAX_LINE_BYTES {
            return Err(header_error(
                self.line,
                format!("longer than {MAX_LINE_BYTES} bytes"),
            ));
        }
        if self.total > MAX_HEADER_BYTES {
            return Err(header_error(
                self.line,
                format!("header longer than {MAX_HEADER_BYTES} bytes"),
            ));
        }
        let text = self.buf.strip_suffix(b"\n").unwrap_or(&self.buf);
        let text = text.strip_suffix(b"\r").unwrap_or(text);
        Ok(Some(String::from_utf8_lossy(text).into_owned()))
    }
}

/// Check the magic line.
fn check_magic(line: Option<&str>) -> Result<(), IoError> {
    let line = line.unwrap_or("");
    let version = line.trim_end().strip_prefix("NRRD000");
    if matches!(version, Some("1" | "2" | "3" | "4" | "5")) {
        Ok(())
    } else {
        Err(IoError::BadMagic {
            found: excerpt(line),
        })
    }
}

/// Handle one header line after the magic.
fn parse_line(fields: &mut Fields, line: &str, number: usize) -> Result<(), IoError> {
    if line.starts_with('#') {
        return Ok(());
    }
    let field_at = line
        .find(": ")
        .or_else(|| line.trim_end().strip_suffix(':').map(str::len));
    let pair_at = line.find(":=");
    match (field_at, pair_at) {
        (_, Some(p)) if field_at.is_none_or(|f| p < f) => Ok(()),
        (Some(f), _) => {
            let (key, value) = line.split_at(f);
            fields.set(key, value.get(1..).unwrap_or("").trim())
        }
        _ => Err(header_error(
            number,
            format!(
                "expected `field: value`, `key:=value` or a `#` comment, got `{}`",
                excerpt(line)
            ),
        )),
    }
}

/// Read the header from the magic line through the blank line that ends it,
/// leaving `reader` at the first byte of data.
pub(super) fn read_header<R: BufRead>(reader: &mut R) -> Result<Layout, IoError> {
    let mut lines = LineReader {
        reader,
        buf: Vec::new(),
        line: 0,
        total: 0,
    };
    check_magic(lines.next_line()?.as_deref())?;
    let mut fields = Fields::default();
    let mut terminated = false;
    while let Some(line) = lines.next_line()? {
        if line.is_empty() {
            terminated = true;
            break;
        }
        parse_line(&mut fields, &line, lines.line)?;
    }
    let layout = fields.into_layout()?;
    // A detached header (`.nhdr`) may end at the end of its file.
    if !terminated && layout.data_file.is_none() {
        return Err(header_error(
            lines.line,
            "end of file before the blank line that ends the header (no data follows)",
        ));
    }
    Ok(layout)
}
