//! Numbers and messages for people: bounded in length, whatever the input.

/// `x` as `{}` prints it when that is short (|x| in `[1e-4, 1e6)`, or 0),
/// otherwise in `{:e}` form, so `1e300` never prints 301 digits.
pub fn num(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-4..1e6).contains(&a) || !a.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `x` to three decimals, or [`num`]'s `{:e}` form outside `[1e-3, 1e6)`.
pub fn num3(x: f64) -> String {
    let a = x.abs();
    if a == 0.0 || (1e-3..1e6).contains(&a) || !a.is_finite() {
        format!("{x:.3}")
    } else {
        format!("{x:.3e}")
    }
}

/// Characters a message line keeps at its start and at its end when longer
/// than [`MAX_LINE_CHARS`].
const KEEP_HEAD: usize = 200;
const KEEP_TAIL: usize = 80;

/// The longest message line printed whole.
pub const MAX_LINE_CHARS: usize = 400;

/// Lines of a message printed before the rest is counted instead.
pub const MAX_LINES: usize = 20;

/// `message` with each line longer than [`MAX_LINE_CHARS`] cut in the middle
/// and at most [`MAX_LINES`] lines, so that an echoed 5 MB key or path
/// cannot flood a terminal or a CI log.
pub fn bounded(message: &str) -> String {
    let lines: Vec<&str> = message.lines().collect();
    let mut out: Vec<String> = lines
        .iter()
        .take(MAX_LINES)
        .map(|line| bound_line(line))
        .collect();
    if lines.len() > MAX_LINES {
        out.push(format!("… and {} more lines", lines.len() - MAX_LINES));
    }
    out.join("\n")
}

fn bound_line(line: &str) -> String {
    let count = line.chars().count();
    if count <= MAX_LINE_CHARS {
        return line.to_string();
    }
    let head: String = line.chars().take(KEEP_HEAD).collect();
    let tail: String = line.chars().skip(count - KEEP_TAIL).collect();
    format!(
        "{head}…[{} characters left out]…{tail}",
        count - KEEP_HEAD - KEEP_TAIL
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_stay_short() {
        assert_eq!(num(1.5), "1.5");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(1e300), "1e300");
        assert_eq!(num(-2.5e-300), "-2.5e-300");
        assert_eq!(num(f64::INFINITY), "inf");
        assert_eq!(num3(-6.2479e115), "-6.248e115");
        assert_eq!(num3(0.25), "0.250");
        for x in [f64::MAX, f64::MIN_POSITIVE, 5e-324, -1e-10, 123456789.0] {
            assert!(num(x).len() <= 24 && num3(x).len() <= 24, "{x}");
        }
    }

    #[test]
    fn long_lines_and_many_lines_are_cut() {
        let key = "k".repeat(5_000_000);
        let msg = format!("unknown key `{key}` in `camera`");
        let b = bounded(&msg);
        assert!(b.chars().count() < MAX_LINE_CHARS + 60, "{}", b.len());
        assert!(b.starts_with("unknown key `kkk") && b.ends_with("` in `camera`"));
        assert!(b.contains("characters left out"));
        let many = vec!["x"; 100].join("\n");
        let b = bounded(&many);
        assert_eq!(b.lines().count(), MAX_LINES + 1);
        assert!(b.ends_with("and 80 more lines"));
        assert_eq!(bounded("short\nlines"), "short\nlines");
        // Multi-byte characters are cut on character boundaries.
        let wide = "é".repeat(1000);
        assert!(bounded(&wide).contains('…'));
    }
}
