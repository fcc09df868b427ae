//! A small reader for XML property lists (Apple's `PropertyList-1.0` DTD),
//! enough for the metadata of InVesalius projects.
//!
//! It accepts the XML declaration, a DOCTYPE, comments and whitespace
//! around elements; the elements `plist`, `dict`, `key`, `array`, `string`,
//! `integer`, `real`, `true`, `false`, `date` and `data` (empty forms such
//! as `<dict/>` too); and the five predefined entities plus numeric
//! character references in text. Nesting deeper than [`MAX_DEPTH`] is
//! refused, so hostile input cannot exhaust the stack.

use std::fmt;

/// Deepest nesting of `dict` and `array` accepted.
pub const MAX_DEPTH: usize = 64;

/// A property-list value.
#[derive(Clone, Debug, PartialEq)]
pub enum PlistValue {
    /// `<dict>`: keys and values in file order.
    Dict(Vec<(String, PlistValue)>),
    /// `<array>`.
    Array(Vec<PlistValue>),
    /// `<string>`.
    String(String),
    /// `<integer>`.
    Integer(i64),
    /// `<real>`.
    Real(f64),
    /// `<true/>` or `<false/>`.
    Bool(bool),
    /// `<date>`, as written.
    Date(String),
    /// `<data>`, base64 text as written.
    Data(String),
}

impl PlistValue {
    /// The value of `key` in a dict (the first if repeated), `None` for a
    /// missing key or a value that is not a dict.
    pub fn get(&self, key: &str) -> Option<&PlistValue> {
        match self {
            PlistValue::Dict(entries) => entries.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// A number (`integer` or `real`) as f64.
    pub fn as_f64(&self) -> Option<f64> {
        match self {
            PlistValue::Integer(i) => Some(*i as f64),
            PlistValue::Real(r) => Some(*r),
            _ => None,
        }
    }

    /// An `integer`.
    pub fn as_i64(&self) -> Option<i64> {
        match self {
            PlistValue::Integer(i) => Some(*i),
            _ => None,
        }
    }

    /// A `string`.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            PlistValue::String(s) => Some(s),
            _ => None,
        }
    }

    /// An `array`.
    pub fn as_array(&self) -> Option<&[PlistValue]> {
        match self {
            PlistValue::Array(a) => Some(a),
            _ => None,
        }
    }

    /// The element name of this kind of value, for error messages.
    pub fn kind(&self) -> &'static str {
        match self {
            PlistValue::Dict(_) => "dict",
            PlistValue::Array(_) => "array",
            PlistValue::String(_) => "string",
            PlistValue::Integer(_) => "integer",
            PlistValue::Real(_) => "real",
            PlistValue::Bool(_) => "true/false",
            PlistValue::Date(_) => "date",
            PlistValue::Data(_) => "data",
        }
    }
}

/// Malformed property-list XML.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlistError {
    /// 1-based line of the problem.
    pub line: usize,
    /// What is wrong.
    pub problem: String,
}

impl fmt::Display for PlistError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.problem)
    }
}

impl std::error::Error for PlistError {}

/// Parse an XML property list: the value inside `<plist>`.
///
/// # Errors
/// Malformed XML, unknown elements, bad numbers, nesting beyond
/// [`MAX_DEPTH`], or text after the end of the list.
pub fn parse_plist(text: &str) -> Result<PlistValue, PlistError> {
    let mut p = Parser { text, pos: 0 };
    p.skip_misc()?;
    let value = match p.open_tag()? {
        Tag::Open("plist") => {
            p.skip_misc()?;
            let value = p.value(0)?;
            p.skip_misc()?;
            p.close_tag("plist")?;
            value
        }
        // A bare value without the `plist` wrapper is accepted too.
        tag => p.value_from(tag, 0)?,
    };
    p.skip_misc()?;
    if p.pos < p.text.len() {
        return Err(p.error("text after the end of the property list"));
    }
    Ok(value)
}

/// An opening tag: `<name ...>` or the empty element `<name/>`.
enum Tag<'a> {
    Open(&'a str),
    Empty(&'a str),
}

struct Parser<'a> {
    text: &'a str,
    pos: usize,
}

impl<'a> Parser<'a> {
    fn rest(&self) -> &'a str {
        self.text.get(self.pos..).unwrap_or("")
    }

    #[cold]
    fn error(&self, problem: impl Into<String>) -> PlistError {
        let upto = self.text.get(..self.pos).unwrap_or(self.text);
        PlistError {
            line: upto.bytes().filter(|&b| b == b'\n').count() + 1,
            problem: problem.into(),
        }
    }

    /// Skip whitespace, comments, the XML declaration and DOCTYPE.
    fn skip_misc(&mut self) -> Result<(), PlistError> {
        loop {
            let rest = self.rest();
            let trimmed = rest.trim_start();
            self.pos += rest.len() - trimmed.len();
            let end = if trimmed.starts_with("<?") {
                trimmed.find("?>").map(|e| e + 2)
            } else if trimmed.starts_with("<!--") {
                trimmed.find("-->").map(|e| e + 3)
            } else if trimmed.starts_with("<!") {
                trimmed.find('>').map(|e| e + 1)
            } else {
                return Ok(());
            };
            match end {
                Some(e) => self.pos += e,
                None => return Err(self.error("unterminated XML declaration or comment")),
            }
        }
    }

    fn open_tag(&mut self) -> Result<Tag<'a>, PlistError> {
        let rest = self.rest();
        if !rest.starts_with('<') || rest.starts_with("</") {
            return Err(self.error(format!("expected an element, found `{}`", excerpt(rest))));
        }
        let end = rest
            .find('>')
            .ok_or_else(|| self.error("unterminated tag"))?;
        let inner = &rest[1..end];
        self.pos += end + 1;
        let (inner, empty) = match inner.strip_suffix('/') {
            Some(i) => (i, true),
            None => (inner, false),
        };
        // Attributes (e.g. `version="1.0"`) are ignored.
        let name = inner.split_whitespace().next().unwrap_or("");
        if name.is_empty() {
            return Err(self.error("empty tag name"));
        }
        Ok(if empty {
            Tag::Empty(name)
        } else {
            Tag::Open(name)
        })
    }

    fn close_tag(&mut self, name: &str) -> Result<(), PlistError> {
        let rest = self.rest();
        let want = format!("</{name}");
        let after = rest
            .strip_prefix(want.as_str())
            .map(str::trim_start)
            .and_then(|r| r.strip_prefix('>'));
        match after {
            Some(a) => {
                self.pos += rest.len() - a.len();
                Ok(())
            }
            None => Err(self.error(format!("expected `</{name}>`, found `{}`", excerpt(rest)))),
        }
    }

    fn value(&mut self, depth: usize) -> Result<PlistValue, PlistError> {
        let tag = self.open_tag()?;
        self.value_from(tag, depth)
    }

    fn value_from(&mut self, tag: Tag<'a>, depth: usize) -> Result<PlistValue, PlistError> {
        let (name, empty) = match tag {
            Tag::Open(n) => (n, false),
            Tag::Empty(n) => (n, true),
        };
        if (name == "dict" || name == "array") && depth >= MAX_DEPTH {
            return Err(self.error(format!("nested deeper than {MAX_DEPTH} levels")));
        }
        match (name, empty) {
            ("true", true) => return Ok(PlistValue::Bool(true)),
            ("false", true) => return Ok(PlistValue::Bool(false)),
            ("dict", true) => return Ok(PlistValue::Dict(Vec::new())),
            ("array", true) => return Ok(PlistValue::Array(Vec::new())),
            ("string", true) => return Ok(PlistValue::String(String::new())),
            ("dict", false) => return self.dict(depth),
            ("array", false) => return self.array(depth),
            ("true" | "false", false) => {
                self.close_tag(name)?;
                return Ok(PlistValue::Bool(name == "true"));
            }
            _ => {}
        }
        if empty {
            return Err(self.error(format!("empty element `<{name}/>` has no value")));
        }
        let text = self.text_until_close(name)?;
        let number_error = |p: &Self, what: &str| {
            p.error(format!(
                "`<{name}>{}</{name}>` is not {what}",
                excerpt(&text)
            ))
        };
        Ok(match name {
            "string" => PlistValue::String(text),
            "date" => PlistValue::Date(text),
            "data" => PlistValue::Data(text),
            "integer" => PlistValue::Integer(
                text.trim()
                    .parse()
                    .map_err(|_| number_error(self, "an integer"))?,
            ),
            "real" => PlistValue::Real(
                text.trim()
                    .parse()
                    .map_err(|_| number_error(self, "a real number"))?,
            ),
            other => return Err(self.error(format!("unknown property-list element `<{other}>`"))),
        })
    }

    fn dict(&mut self, depth: usize) -> Result<PlistValue, PlistError> {
        let mut entries = Vec::new();
        loop {
            self.skip_misc()?;
            if self.rest().starts_with("</") {
                self.close_tag("dict")?;
                return Ok(PlistValue::Dict(entries));
            }
            let key = match self.open_tag()? {
                Tag::Open("key") => self.text_until_close("key")?,
                Tag::Empty("key") => String::new(),
                Tag::Open(other) | Tag::Empty(other) => {
                    return Err(self.error(format!("expected `<key>` in a dict, found `<{other}>`")))
                }
            };
            self.skip_misc()?;
            let value = self.value(depth + 1)?;
            entries.push((key, value));
        }
    }

    fn array(&mut self, depth: usize) -> Result<PlistValue, PlistError> {
        let mut items = Vec::new();
        loop {
            self.skip_misc()?;
            if self.rest().starts_with("</") {
                self.close_tag("array")?;
                return Ok(PlistValue::Array(items));
            }
            items.push(self.value(depth + 1)?);
        }
    }

    /// The text up to `</name>`, entities decoded; consumes the close tag.
    fn text_until_close(&mut self, name: &str) -> Result<String, PlistError> {
        let rest = self.rest();
        let end = rest
            .find('<')
            .ok_or_else(|| self.error(format!("unterminated `<{name}>`")))?;
        let raw = &rest[..end];
        let text = decode_entities(raw).map_err(|p| self.error(p))?;
        self.pos += end;
        self.close_tag(name)?;
        Ok(text)
    }
}

/// Replace `&lt;` `&gt;` `&amp;` `&quot;` `&apos;` and `&#N;`/`&#xH;`.
fn decode_entities(raw: &str) -> Result<String, String> {
    let mut out = String::with_capacity(raw.len());
    let mut rest = raw;
    while let Some(amp) = rest.find('&') {
        out.push_str(&rest[..amp]);
        let after = &rest[amp + 1..];
        let semi = after
            .find(';')
            .filter(|&s| s <= 10)
            .ok_or_else(|| format!("unterminated entity in `{}`", excerpt(raw)))?;
        let entity = &after[..semi];
        let c = match entity {
            "lt" => '<',
            "gt" => '>',
            "amp" => '&',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code = if let Some(hex) = entity.strip_prefix("#x") {
                    u32::from_str_radix(hex, 16).ok()
                } else if let Some(dec) = entity.strip_prefix('#') {
                    dec.parse::<u32>().ok()
                } else {
                    None
                };
                code.and_then(char::from_u32)
                    .ok_or_else(|| format!("unknown entity `&{entity};`"))?
            }
        };
        out.push(c);
        rest = &after[semi + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

/// At most 40 characters of `s`, control characters escaped.
fn excerpt(s: &str) -> String {
    let mut out = String::new();
    for (n, c) in s.chars().enumerate() {
        if n == 40 {
            out.push('…');
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_invesalius_layout() {
        let text = r#"<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE plist PUBLIC "-//Apple Computer//DTD PLIST 1.0//EN" "http://www.apple.com/DTDs/PropertyList-1.0.dtd">
<plist version="1.0">
<dict>
	<key>annotations</key>
	<dict>
	</dict>
	<key>matrix</key>
	<dict>
		<key>dtype</key>
		<string>int16</string>
		<key>shape</key>
		<array>
			<integer>108</integer>
			<integer>256</integer>
			<integer>-3</integer>
		</array>
	</dict>
	<key>name</key>
	<string>M&amp;M &#233;</string>
	<key>spacing</key>
	<array><real>0.95703119999999997</real><real>1.5</real></array>
	<key>visible</key>
	<true/>
	<!-- a comment -->
</dict>
</plist>
"#;
        let v = parse_plist(text).expect("parses");
        let m = v.get("matrix").expect("matrix");
        assert_eq!(m.get("dtype").and_then(PlistValue::as_str), Some("int16"));
        let shape: Vec<i64> = m
            .get("shape")
            .and_then(PlistValue::as_array)
            .expect("shape")
            .iter()
            .filter_map(PlistValue::as_i64)
            .collect();
        assert_eq!(shape, vec![108, 256, -3]);
        assert_eq!(v.get("name").and_then(PlistValue::as_str), Some("M&M é"));
        let sp = v.get("spacing").and_then(PlistValue::as_array).expect("sp");
        assert_eq!(sp[0].as_f64(), Some(0.957_031_2));
        assert_eq!(v.get("visible"), Some(&PlistValue::Bool(true)));
        assert_eq!(v.get("annotations"), Some(&PlistValue::Dict(vec![])));
    }

    #[test]
    fn errors_name_the_line_and_problem() {
        let e =
            parse_plist("<plist>\n<dict>\n<key>a</key>\n<integer>1.5</integer>\n</dict></plist>")
                .unwrap_err();
        assert_eq!(e.line, 4, "{e}");
        assert!(e.problem.contains("not an integer"), "{e}");
        let e = parse_plist("<plist><dict><key>a</key><blob>1</blob></dict></plist>").unwrap_err();
        assert!(
            e.problem.contains("unknown property-list element `<blob>`"),
            "{e}"
        );
        let e = parse_plist("<plist><dict><string>a</string></dict></plist>").unwrap_err();
        assert!(e.problem.contains("expected `<key>`"), "{e}");
        let e = parse_plist("<plist><array><integer>1</integer>").unwrap_err();
        assert!(e.problem.contains("expected an element"), "{e}");
        let e = parse_plist("<plist><true/></plist> trailing").unwrap_err();
        assert!(e.problem.contains("after the end"), "{e}");
        let e = parse_plist("<plist><string>&bogus;</string></plist>").unwrap_err();
        assert!(e.problem.contains("unknown entity"), "{e}");
    }

    #[test]
    fn deep_nesting_is_refused_not_a_stack_overflow() {
        let deep = "<array>".repeat(100_000);
        let e = parse_plist(&format!("<plist>{deep}")).unwrap_err();
        assert!(e.problem.contains("nested deeper than 64"), "{e}");
        let ok = format!("{}{}", "<array>".repeat(64), "</array>".repeat(64));
        assert!(parse_plist(&ok).is_ok());
    }
}
