//! NRRD `space`, `space directions` and `space origin` as a volume's
//! [`Orientation`] in RAS (`right-anterior-superior`), and back.

use super::error::{excerpt, format_error, IoError};
use fvr_engine::volume::Orientation;

/// The sign of each world axis to reach RAS from a patient `space`
/// (`None` for spaces that are not a patient's: scanner, 3D-right-handed,
/// or 2D and time spaces).
fn to_ras_signs(space: &str) -> Option<[f64; 3]> {
    match space.trim().to_ascii_lowercase().as_str() {
        "right-anterior-superior" | "ras" => Some([1.0, 1.0, 1.0]),
        "left-anterior-superior" | "las" => Some([-1.0, 1.0, 1.0]),
        "left-posterior-superior" | "lps" => Some([-1.0, -1.0, 1.0]),
        _ => None,
    }
}

/// A vector `(x,y,z)`.
fn parse_vector(field: &'static str, text: &str) -> Result<[f64; 3], IoError> {
    let bad = || {
        format_error(
            "NRRD header",
            field,
            format!(
                "expected a vector `(x,y,z)`, got `{}`",
                excerpt(text.trim())
            ),
        )
    };
    let inner = text
        .trim()
        .strip_prefix('(')
        .and_then(|r| r.strip_suffix(')'))
        .ok_or_else(bad)?;
    let v: Vec<f64> = inner
        .split(',')
        .map(|c| c.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok([x, y, z]),
        _ => Err(bad()),
    }
}

/// The orientation of a 3D volume with a patient `space`, the three
/// `space directions` vectors `directions` (in the file's space) and an
/// optional `space origin`. `Ok(None)` without a patient space or without
/// three vectors.
///
/// # Errors
/// A malformed `space origin`.
pub(crate) fn orientation(
    space: Option<&str>,
    directions: &[[f64; 3]],
    origin: Option<&str>,
) -> Result<Option<Orientation>, IoError> {
    let Some(signs) = space.and_then(to_ras_signs) else {
        return Ok(None);
    };
    let origin = match origin {
        Some(o) => parse_vector("space origin", o)?,
        None => [0.0; 3],
    };
    let [a, b, c] = directions else {
        return Ok(None);
    };
    let columns = [a, b, c];
    let m: [[f64; 3]; 3] =
        std::array::from_fn(|w| std::array::from_fn(|ax| signs[w] * columns[ax][w]));
    let origin = std::array::from_fn(|w| signs[w] * origin[w]);
    Ok(Orientation::from_columns(m, origin))
}

/// The header lines that record `orientation` for voxels `spacing` mm
/// apart: `space: right-anterior-superior`, `space directions` (each axis'
/// unit vector times its spacing) and `space origin`.
pub(crate) fn header_lines(orientation: &Orientation, spacing: [f64; 3]) -> String {
    let d = &orientation.direction;
    // `+ 0.0` writes −0 (from LPS sign flips) as 0.
    let vector = |v: [f64; 3]| format!("({:?},{:?},{:?})", v[0] + 0.0, v[1] + 0.0, v[2] + 0.0);
    let axes: Vec<String> = (0..3)
        .map(|a| vector(std::array::from_fn(|w| d[w][a] * spacing[a])))
        .collect();
    format!(
        "space: right-anterior-superior\nspace directions: {}\nspace origin: {}\n",
        axes.join(" "),
        vector(orientation.origin)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lps_becomes_ras_and_back() {
        let dirs = [[-2.0, 0.0, 0.0], [0.0, -2.0, 0.0], [0.0, 0.0, 3.0]];
        let o = orientation(Some("left-posterior-superior"), &dirs, Some("(10, 20,30)"))
            .unwrap()
            .unwrap();
        assert_eq!(o.direction, Orientation::IDENTITY.direction);
        assert_eq!(o.origin, [-10.0, -20.0, 30.0]);
        let lines = header_lines(&o, [2.0, 2.0, 3.0]);
        assert!(
            lines.contains("space directions: (2.0,0.0,0.0) (0.0,2.0,0.0) (0.0,0.0,3.0)"),
            "{lines}"
        );
        assert!(
            lines.contains("space origin: (-10.0,-20.0,30.0)"),
            "{lines}"
        );
        assert_eq!(orientation(Some("scanner-xyz"), &dirs, None).unwrap(), None);
        assert_eq!(orientation(None, &dirs, None).unwrap(), None);
        assert!(orientation(Some("RAS"), &dirs, Some("(1,2)")).is_err());
    }
}
