//! `--stats-json`: one JSON object on one line, members as `"key": value`
//! separated by `, `, numbers as Rust's `{}` prints them (so `1`, not
//! `1.0`), non-finite numbers as `null`.

use std::io::{self, Write};

use serde::Serialize;
use serde_json::ser::Formatter;
use serde_json::value::RawValue;

/// The formatter of the one-line layout.
struct OneLine;

impl Formatter for OneLine {
    fn begin_array_value<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        if first {
            Ok(())
        } else {
            w.write_all(b", ")
        }
    }

    fn begin_object_key<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        self.begin_array_value(w, first)
    }

    fn begin_object_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(b": ")
    }

    fn write_f64<W: ?Sized + Write>(&mut self, w: &mut W, value: f64) -> io::Result<()> {
        write!(w, "{value}")
    }
}

/// `value` as one line of JSON.
pub(crate) fn one_line(value: &impl Serialize) -> String {
    let mut out = Vec::new();
    let mut ser = serde_json::Serializer::with_formatter(&mut out, OneLine);
    value
        .serialize(&mut ser)
        .expect("statistics serialize to memory");
    String::from_utf8(out).expect("serde_json writes UTF-8")
}

/// Three numbers as Rust's `{:?}` prints them (`[1.0, 0.5, 2.0]`).
pub(crate) fn debug_triple(v: [f64; 3]) -> Box<RawValue> {
    RawValue::from_string(format!("{v:?}")).expect("finite numbers are JSON")
}
