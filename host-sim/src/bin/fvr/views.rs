//! The views of `fvr project`: read from a file (CSV or JSON) or drawn at
//! random, and written back as the CSV the file reader takes.

use std::path::Path;

use fvr_core::geometry::View;
use fvr_engine::volume::phantom::SplitMix64;

use crate::Error;

/// The largest views file read (64 MiB: about a million views).
pub(crate) const VIEWS_MAX_BYTES: u64 = 64 << 20;

/// The most views one job renders.
pub(crate) const MAX_VIEWS: usize = 1_000_000;

/// Read the views of `path`: JSON when its first non-blank character is `[`,
/// else CSV. A view without an up vector takes `default_up`.
///
/// CSV: one view a line, `dx,dy,dz` or `dx,dy,dz,ux,uy,uz` (commas or
/// blanks between numbers); blank lines, `#` comments and a first line of
/// names (`dx,dy,dz,...`) are skipped. JSON: a list of `[dx,dy,dz]`,
/// `[dx,dy,dz,ux,uy,uz]` or `{"dir": [..], "up": [..]}` (`up` optional).
///
/// # Errors
/// The file cannot be read, or a line or item is not a view; the message
/// names the file and the line (CSV) or the item (JSON).
pub(crate) fn read_views(path: &Path, default_up: [f64; 3]) -> Result<Vec<View>, Error> {
    let text = fvr_host::io::read_small_text(path, "views file", VIEWS_MAX_BYTES)?;
    let name = path.display();
    let views = if text.trim_start().starts_with('[') {
        parse_json(&text, default_up).map_err(|e| format!("{name}: {e}"))?
    } else {
        parse_csv(&text, default_up).map_err(|e| format!("{name}: {e}"))?
    };
    if views.is_empty() {
        return Err(format!("{name}: no views in the file").into());
    }
    if views.len() > MAX_VIEWS {
        return Err(format!("{name}: {} views; at most {MAX_VIEWS}", views.len()).into());
    }
    Ok(views)
}

/// A view from 3 or 6 numbers, every one finite.
fn view_of(numbers: &[f64], default_up: [f64; 3]) -> Result<View, String> {
    if let Some(bad) = numbers.iter().find(|v| !v.is_finite()) {
        return Err(format!("{bad} is not a finite number"));
    }
    match *numbers {
        [dx, dy, dz] => Ok(View {
            dir: [dx, dy, dz],
            up: default_up,
        }),
        [dx, dy, dz, ux, uy, uz] => Ok(View {
            dir: [dx, dy, dz],
            up: [ux, uy, uz],
        }),
        _ => Err(format!(
            "{} numbers; a view is 3 (dx,dy,dz) or 6 (dx,dy,dz,ux,uy,uz)",
            numbers.len()
        )),
    }
}

fn parse_csv(text: &str, default_up: [f64; 3]) -> Result<Vec<View>, String> {
    let mut views = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        let numbers: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        match numbers {
            Ok(numbers) => views
                .push(view_of(&numbers, default_up).map_err(|e| format!("line {}: {e}", i + 1))?),
            // A header of names, only before the first view.
            Err(_) if views.is_empty() && fields.iter().all(|f| f.parse::<f64>().is_err()) => {}
            Err(_) => {
                let bad = fields
                    .iter()
                    .find(|f| f.parse::<f64>().is_err())
                    .unwrap_or(&"");
                return Err(format!(
                    "line {}: `{}` is not a number",
                    i + 1,
                    fvr_host::text::bounded(bad)
                ));
            }
        }
    }
    Ok(views)
}

fn parse_json(text: &str, default_up: [f64; 3]) -> Result<Vec<View>, String> {
    use serde_json::Value;
    let value: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let Value::Array(items) = value else {
        return Err("not a JSON list of views".into());
    };
    let numbers = |v: &Value| -> Result<Vec<f64>, String> {
        let Value::Array(a) = v else {
            return Err("expected a list of numbers".into());
        };
        a.iter()
            .map(|x| x.as_f64().ok_or_else(|| format!("`{x}` is not a number")))
            .collect()
    };
    items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            let view = match item {
                Value::Array(_) => view_of(&numbers(item)?, default_up),
                Value::Object(o) => {
                    if let Some(k) = o.keys().find(|k| *k != "dir" && *k != "up") {
                        return Err(format!(
                            "view {i}: unknown key `{}` (keys: dir, up)",
                            fvr_host::text::bounded(k)
                        ));
                    }
                    let dir = o.get("dir").ok_or(format!("view {i}: no `dir`"))?;
                    let mut all = numbers(dir)?;
                    if all.len() != 3 {
                        return Err(format!("view {i}: `dir` needs 3 numbers"));
                    }
                    if let Some(up) = o.get("up") {
                        let up = numbers(up)?;
                        if up.len() != 3 {
                            return Err(format!("view {i}: `up` needs 3 numbers"));
                        }
                        all.extend(up);
                    }
                    view_of(&all, default_up)
                }
                _ => Err("expected a list or an object".into()),
            };
            view.map_err(|e| {
                if e.starts_with("view ") {
                    e
                } else {
                    format!("view {i}: {e}")
                }
            })
        })
        .collect()
}

/// `count` views at uniformly random rotations from `seed`: the direction
/// uniform on the sphere (a point of the unit ball, normalised) and the roll
/// about it uniform on [0, 2π), which together are the uniform (Haar)
/// distribution of rotations. The up vector is exactly orthogonal to the
/// direction, so the image's up is that vector.
pub(crate) fn random_views(count: usize, seed: u64) -> Vec<View> {
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|_| {
            let d = loop {
                let v = [0, 1, 2].map(|_| 2.0 * rng.next_f64() - 1.0);
                let r2: f64 = v.iter().map(|x| x * x).sum();
                if r2 > 1e-6 && r2 < 1.0 {
                    break v.map(|x| x / r2.sqrt());
                }
            };
            // A unit vector orthogonal to d (from the axis least along d),
            // the second one d × a, and the roll between them.
            let e = if d[2].abs() < 0.9 {
                [0.0, 0.0, 1.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let along = e[0] * d[0] + e[1] * d[1] + e[2] * d[2];
            let a = [0, 1, 2].map(|i| e[i] - along * d[i]);
            let na = a.iter().map(|x| x * x).sum::<f64>().sqrt();
            let a = a.map(|x| x / na);
            let b = [
                d[1] * a[2] - d[2] * a[1],
                d[2] * a[0] - d[0] * a[2],
                d[0] * a[1] - d[1] * a[0],
            ];
            let roll = 2.0 * std::f64::consts::PI * rng.next_f64();
            let (s, c) = roll.sin_cos();
            View {
                dir: d,
                up: [0, 1, 2].map(|i| c * a[i] + s * b[i]),
            }
        })
        .collect()
}

/// The CSV of `views` that [`read_views`] reads back exactly (Rust's
/// shortest round-trip form of each number).
pub(crate) fn views_csv(views: &[View]) -> String {
    let mut out = String::from("dx,dy,dz,ux,uy,uz\n");
    for v in views {
        let [dx, dy, dz] = v.dir;
        let [ux, uy, uz] = v.up;
        out.push_str(&format!("{dx:?},{dy:?},{dz:?},{ux:?},{uy:?},{uz:?}\n"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const UP: [f64; 3] = [0.0, 0.0, 1.0];

    #[test]
    fn csv_takes_three_or_six_numbers_comments_and_a_header() {
        let text = "dx,dy,dz,ux,uy,uz\n# a comment\n1,0,0\n\n0 1 0  0 0 1 # trailing\n";
        let v = parse_csv(text, UP).unwrap();
        assert_eq!(v.len(), 2);
        assert_eq!(v[0].dir, [1.0, 0.0, 0.0]);
        assert_eq!(v[0].up, UP);
        assert_eq!(v[1].up, [0.0, 0.0, 1.0]);
        for (bad, needle) in [
            ("1,0,0\n1,x,0\n", "line 2: `x` is not a number"),
            ("1,0\n", "line 1: 2 numbers"),
            ("1,0,0,1\n", "4 numbers"),
            ("1,nan,0\n", "not a finite number"),
            ("1,0,0\ndx,dy,dz\n", "line 2"),
        ] {
            let e = parse_csv(bad, UP).unwrap_err();
            assert!(e.contains(needle), "{bad:?}: {e}");
        }
    }

    #[test]
    fn json_takes_lists_and_objects() {
        let v = parse_json(
            r#"[[1,0,0], [0,1,0,1,0,0], {"dir": [0,0,1], "up": [0,1,0]}, {"dir": [1,1,1]}]"#,
            UP,
        )
        .unwrap();
        assert_eq!(v.len(), 4);
        assert_eq!(v[1].up, [1.0, 0.0, 0.0]);
        assert_eq!(v[2].dir, [0.0, 0.0, 1.0]);
        assert_eq!(v[3].up, UP);
        for (bad, needle) in [
            ("{}", "not a JSON list"),
            ("[1,2", "not JSON"),
            (
                r#"[{"dir": [1,0,0], "upp": [0,0,1]}]"#,
                "view 0: unknown key `upp`",
            ),
            (r#"[[1,0,0], {"up": [0,0,1]}]"#, "view 1: no `dir`"),
            (r#"[[1,"a",0]]"#, "is not a number"),
            (r#"[{"dir": [1,0]}]"#, "view 0: `dir` needs 3"),
        ] {
            let e = parse_json(bad, UP).unwrap_err();
            assert!(e.contains(needle), "{bad}: {e}");
        }
    }

    #[test]
    fn random_views_are_orthonormal_reproducible_and_cover_the_sphere() {
        let views = random_views(4000, 7);
        assert_eq!(views, random_views(4000, 7));
        assert_ne!(views[..10], random_views(10, 8)[..]);
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let mut mean = [0.0; 3];
        let mut octants = [0usize; 8];
        for v in &views {
            assert!((dot(v.dir, v.dir) - 1.0).abs() < 1e-12);
            assert!((dot(v.up, v.up) - 1.0).abs() < 1e-12);
            assert!(dot(v.dir, v.up).abs() < 1e-12);
            for a in 0..3 {
                mean[a] += v.dir[a] / views.len() as f64;
            }
            let o = (0..3).fold(0, |o, a| o * 2 + usize::from(v.dir[a] > 0.0));
            octants[o] += 1;
        }
        // Uniform on the sphere: the mean near 0 (σ = 1/√(3·4000) ≈ 0.009
        // per axis) and each octant near an eighth (σ ≈ 21 of 500).
        assert!(mean.iter().all(|m| m.abs() < 0.05), "{mean:?}");
        assert!(
            octants.iter().all(|&c| (400..600).contains(&c)),
            "{octants:?}"
        );
    }

    #[test]
    fn the_csv_written_reads_back_exactly() {
        let views = random_views(20, 3);
        assert_eq!(parse_csv(&views_csv(&views), UP).unwrap(), views);
    }
}
