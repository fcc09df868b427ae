//! Helpers shared by the `fvr` end-to-end tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use fvr_engine::volume::Volume;

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

/// Each command line of `cases`, run in `dir` (as [`fvr_line`]), is
/// refused as [`assert_error`] checks: exit status 2, no panic, every
/// needle on stderr. A failure names the line.
pub fn assert_refused(dir: &Path, cases: &[(&str, &[&str])]) {
    for (line, needles) in cases {
        let out = fvr_line(line, dir);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "`fvr {line}`: {err}");
        assert!(!err.contains("panicked"), "`fvr {line}`: {err}");
        for n in *needles {
            assert!(err.contains(n), "`fvr {line}`: `{n}` not in: {err}");
        }
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

/// Run `command` (as [`fvr_line`]) in `dir`; asserts exit status 0 (as
/// [`assert_ok`]) and returns stdout.
pub fn fvr_ok(command: &str, dir: &Path) -> String {
    assert_ok(&fvr_line(command, dir))
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

/// Every frame of the PNG or APNG at `path`, decoded: its info and the
/// bytes of each frame. A decoding error panics naming the path and frame.
pub fn png_frames(path: &Path) -> (png::Info<'static>, Vec<Vec<u8>>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let info = reader.info().clone();
    let count = info.animation_control.map_or(1, |a| a.num_frames as usize);
    let frames = (0..count)
        .map(|i| {
            let mut buf = vec![0; reader.output_buffer_size().unwrap()];
            let frame = reader
                .next_frame(&mut buf)
                .unwrap_or_else(|e| panic!("{} frame {i}: {e}", path.display()));
            buf.truncate(frame.buffer_size());
            buf
        })
        .collect();
    (info, frames)
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

/// The first line of `stdout` that starts with `{`, parsed as JSON (the
/// `--stats-json` object among other output).
pub fn json_line(stdout: &[u8]) -> serde_json::Value {
    let text = String::from_utf8_lossy(stdout);
    let line = text
        .lines()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("no JSON line in: {text}"));
    serde_json::from_str(line).unwrap()
}

/// Run `command` (as [`fvr_line`]) in `dir`, which must succeed
/// ([`assert_ok`]): its `--stats-json` object ([`json_line`]) and its
/// stderr.
pub fn stats_json(command: &str, dir: &Path) -> (serde_json::Value, String) {
    let out = fvr_line(command, dir);
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (json_line(&out.stdout), err)
}

/// A volume of `dims` filled with uniform values in `[0, 1)` from a
/// xorshift stream seeded with `seed`: white noise, every frequency
/// present, content at every face.
pub fn xorshift_noise(dims: [usize; 3], seed: u64) -> Volume {
    let mut state = seed;
    let data = (0..dims[0] * dims[1] * dims[2])
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        })
        .collect();
    Volume::new(dims, data)
}

/// A volume of `dims` filled with `mean` plus uniform values in `[−1, 1)`
/// from Knuth's MMIX linear congruential stream seeded with `seed`: white
/// noise, so the spectrum has energy up to the cube's faces and wrapped
/// taps carry weight.
pub fn lcg_noise(dims: [usize; 3], seed: u64, mean: f32) -> Volume {
    let mut state = seed;
    let data = (0..dims.iter().product::<usize>())
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            mean + ((state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0)
        })
        .collect();
    Volume::new(dims, data)
}
