//! The libFuzzer target over command lines and scene files: `fvr` itself,
//! compiled by `cargo fuzz` (`fuzz/`, target `cli`) with `--cfg fuzzing`.
//!
//! An input is NUL-separated: first the text of a scene file (written to
//! `s.toml`), then the arguments. Every run gets `--quiet --max-memory
//! 256M`, works in one private directory, and is confined to it: arguments
//! with a path separator or `..` are skipped, and only `render`,
//! `turntable`, `compare` and `convert` run (the studies take minutes by
//! design).
//! Whatever the input, `fvr` must return (never panic or abort), within
//! the memory limit that libFuzzer's `-rss_limit_mb` enforces.

use std::path::PathBuf;
use std::sync::OnceLock;

libfuzzer_sys::fuzz_target!(|data: &[u8]| run_case(data));

/// The private working directory, entered once per process.
fn workdir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("fvr-fuzz-cli-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a fuzzing directory");
        std::env::set_current_dir(&dir).expect("enter the fuzzing directory");
        dir
    })
}

fn run_case(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let mut parts = text.split('\0');
    let scene = parts.next().unwrap_or("");
    let args: Vec<&str> = parts.collect();
    let confined = |a: &&str| !(a.contains('/') || a.contains('\\') || a.contains(".."));
    let allowed = matches!(
        args.first(),
        Some(&("render" | "turntable" | "compare" | "convert"))
    );
    if !allowed || args.len() > 48 || !args.iter().all(confined) {
        return;
    }
    let dir = workdir();
    if std::fs::write(dir.join("s.toml"), scene).is_err() {
        return;
    }
    let mut line = vec!["fvr", "--quiet", "--max-memory", "256M"];
    line.extend(args);
    let _ = crate::run(line);
}
