//! Helpers shared by the `fvr` end-to-end tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run `fvr` with `args` in `dir`.
pub fn fvr(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fvr"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("fvr runs")
}

/// A fresh directory for one test, unique to this process.
pub fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("fvr-cli-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Exit status 2, a message on stderr containing every needle, no panic.
pub fn assert_error(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for n in needles {
        assert!(err.contains(n), "`{n}` not in: {err}");
    }
}

/// Exit status 0; returns stdout. Panics with stderr otherwise.
pub fn assert_ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Run `fvr` with the words of `command` (split at white space) in `dir`.
pub fn fvr_line(command: &str, dir: &Path) -> Output {
    fvr(&command.split_whitespace().collect::<Vec<_>>(), dir)
}

/// Run `command` (as [`fvr_line`]) in a fresh directory named `name` (as
/// [`temp_dir`]); returns the directory and the output.
pub fn fvr_in(name: &str, command: &str) -> (PathBuf, Output) {
    let dir = temp_dir(name);
    let out = fvr_line(command, &dir);
    (dir, out)
}

/// The text of the file `name` in `dir` (an output a test checks).
pub fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The grey bytes of an 8-bit PNG and its width.
#[allow(dead_code)]
pub fn grey_png(path: &Path) -> (usize, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let frame = reader.next_frame(&mut buf).unwrap();
    assert_eq!(frame.color_type, png::ColorType::Grayscale);
    buf.truncate(frame.buffer_size());
    (frame.width as usize, buf)
}
