//! Nothing lost, ever: every output is written to an exclusively created
//! temporary file beside it and renamed over it when whole, so a full disk,
//! a signal, a closed pipe, a planted link or a second job never destroys
//! the previous file nor leaves a truncated one.

mod common;

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{assert_error, assert_ok, fvr_line, png_frames, temp_dir};
use fvr_host::io::atomic::{write_bytes, Output};

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Every frame of the (A)PNG at `path` decodes; returns the frame count.
fn decoded_frames(path: &Path) -> usize {
    png_frames(path).1.len()
}

/// A file-size limit (`ulimit -f`, SIGXFSZ ignored so a write past it fails
/// with EFBIG as on a full disk): the previous output stays whole and
/// nothing is left beside it.
#[test]
fn a_failed_write_keeps_the_previous_output() {
    let dir = temp_dir("outputs-full");
    for name in ["x.nrrd", "x.png"] {
        std::fs::write(dir.join(name), b"the previous output").unwrap();
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -f 1; trap '' XFSZ; exec \"$0\" render gaussians@128 --dir 1,0,0 \
                 --out {name} --quiet"
            ))
            .arg(env!("CARGO_BIN_EXE_fvr"))
            .current_dir(&dir)
            .output()
            .unwrap();
        assert_error(&out, &[name]);
        assert_eq!(
            std::fs::read(dir.join(name)).unwrap(),
            b"the previous output",
            "{name} was clobbered"
        );
    }
    assert_eq!(names(&dir), ["x.nrrd", "x.png"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Files planted under the old fixed temporary name (a link to an input, a
/// user's file) are neither followed, written nor removed.
#[test]
#[cfg(unix)]
fn planted_temporary_names_are_left_alone() {
    let dir = temp_dir("outputs-planted");
    let out = fvr_line("convert sphere@16 --out vol.nrrd", &dir);
    assert_ok(&out);
    let volume = std::fs::read(dir.join("vol.nrrd")).unwrap();
    std::os::unix::fs::symlink("vol.nrrd", dir.join(".y.apng.partial")).unwrap();
    std::fs::write(dir.join(".z.apng.partial"), b"a user's file").unwrap();
    for name in ["y.apng", "z.apng"] {
        let out = fvr_line(
            &format!("turntable vol.nrrd --frames 3 --out {name} --quiet"),
            &dir,
        );
        assert_ok(&out);
        assert_eq!(decoded_frames(&dir.join(name)), 3);
    }
    assert_eq!(std::fs::read(dir.join("vol.nrrd")).unwrap(), volume);
    assert_eq!(
        std::fs::read(dir.join(".z.apng.partial")).unwrap(),
        b"a user's file"
    );
    assert_eq!(
        names(&dir),
        [
            ".y.apng.partial",
            ".z.apng.partial",
            "vol.nrrd",
            "y.apng",
            "z.apng"
        ]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Jobs writing one output at once each write a whole file of their own;
/// the last rename wins and the result decodes.
#[test]
fn concurrent_turntables_never_mix_their_frames() {
    let dir = temp_dir("outputs-concurrent");
    let jobs: Vec<_> = (0..4)
        .map(|_| {
            Command::new(env!("CARGO_BIN_EXE_fvr"))
                .args(["turntable", "gaussians@48", "--frames", "40"])
                .args(["--out", "same.apng", "--quiet"])
                .current_dir(&dir)
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for job in jobs {
        assert_ok(&job.wait_with_output().unwrap());
    }
    assert_eq!(decoded_frames(&dir.join("same.apng")), 40);
    assert_eq!(names(&dir), ["same.apng"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A 250-byte output name is valid (NAME_MAX is 255): the temporary name
/// does not depend on it.
#[test]
fn a_long_output_name_is_not_refused_for_its_temporary_file() {
    let dir = temp_dir("outputs-long");
    let name = format!("{}.apng", "t".repeat(245));
    assert_eq!(name.len(), 250);
    let out = fvr_line(
        &format!("turntable sphere@16 --frames 2 --out {name}"),
        &dir,
    );
    assert_ok(&out);
    assert_eq!(decoded_frames(&dir.join(&name)), 2);
    assert_eq!(names(&dir), [name]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// SIGINT (and SIGTERM) during a long turntable: exit status 130, the
/// previous animation as it was, no temporary file left.
#[test]
#[cfg(unix)]
fn a_signal_removes_the_temporary_file_and_keeps_the_previous_output() {
    for signal in ["-INT", "-TERM"] {
        let dir = temp_dir(&format!("outputs-signal{signal}"));
        std::fs::write(dir.join("spin.apng"), b"the previous animation").unwrap();
        let mut job = Command::new(env!("CARGO_BIN_EXE_fvr"))
            // A fixed window: each frame is encoded as it is rendered, so
            // the temporary file exists while most of the turn is to come.
            .args(["turntable", "gaussians@64", "--frames", "3600"])
            .args(["--window", "2", "--level", "1"])
            .args(["--out", "spin.apng", "--quiet"])
            .current_dir(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Wait for the frames to be written (the temporary file exists).
        let t0 = Instant::now();
        while names(&dir).len() < 2 {
            assert!(t0.elapsed() < Duration::from_secs(60), "no temporary file");
            std::thread::sleep(Duration::from_millis(20));
        }
        std::thread::sleep(Duration::from_millis(200));
        let kill = Command::new("kill")
            .args([signal, &job.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        let status = job.wait().unwrap();
        let mut err = String::new();
        std::io::Read::read_to_string(&mut job.stderr.take().unwrap(), &mut err).unwrap();
        assert_eq!(status.code(), Some(130), "{signal}: {status:?} {err}");
        assert!(err.contains("interrupted"), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert_eq!(
            std::fs::read(dir.join("spin.apng")).unwrap(),
            b"the previous animation"
        );
        assert_eq!(names(&dir), ["spin.apng"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// `fvr render … --stats | head -1`: the reader is gone before fvr prints.
/// No panic (exit 101): the image is written whole and the exit status is 0.
#[test]
fn a_closed_pipe_is_not_a_panic() {
    let dir = temp_dir("outputs-epipe");
    for args in [
        &[
            "render", "teapot", "--dir", "1,0,0", "--out", "t.png", "--stats",
        ][..],
        &[
            "render",
            "sphere@16",
            "--dir",
            "1,0,0",
            "--out",
            "t.png",
            "--stats-json",
        ],
        &["turntable", "sphere@16", "--frames", "2", "--out", "t.apng"],
        &["compare", "a.nrrd", "a.nrrd"],
    ] {
        if args[0] == "compare" {
            let out = fvr_line("render sphere@16 --dir 1,0,0 --out a.nrrd", &dir);
            assert_ok(&out);
        }
        let mut job = Command::new(env!("CARGO_BIN_EXE_fvr"))
            .args(args)
            .current_dir(&dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(job.stdout.take());
        let out = job.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    assert_eq!(decoded_frames(&dir.join("t.png")), 1);
    assert_eq!(decoded_frames(&dir.join("t.apng")), 2);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The library's own guarantees, under the program's: a dropped output
/// leaves the previous file, a commit replaces it, a long name fits, and a
/// link at the target is replaced, not followed.
#[test]
fn commit_replaces_and_drop_leaves_the_old_file() {
    let dir = temp_dir("atomic-commit");
    let target = dir.join("a.png");
    std::fs::write(&target, b"old").unwrap();
    let mut out = Output::create(&target).unwrap();
    out.write_all(b"half").unwrap();
    assert_eq!(names(&dir).len(), 2);
    drop(out);
    assert_eq!(std::fs::read(&target).unwrap(), b"old");
    assert_eq!(names(&dir), ["a.png"]);
    write_bytes(&target, b"new").unwrap();
    assert_eq!(std::fs::read(&target).unwrap(), b"new");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Readable by others under the usual umask 022, as `File::create` makes it.
        let mode = std::fs::metadata(&target).unwrap().permissions().mode();
        assert_eq!(mode & 0o600, 0o600, "mode {mode:o}");
    }
    assert_eq!(names(&dir), ["a.png"]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_long_name_fits() {
    let dir = temp_dir("atomic-long");
    let target = dir.join(format!("{}.apng", "x".repeat(250)));
    write_bytes(&target, b"ok").unwrap();
    assert_eq!(std::fs::read(&target).unwrap(), b"ok");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
#[cfg(unix)]
fn a_symlinked_target_is_replaced_not_followed() {
    let dir = temp_dir("atomic-link");
    let victim = dir.join("victim.nrrd");
    std::fs::write(&victim, b"input").unwrap();
    let target = dir.join("out.png");
    std::os::unix::fs::symlink(&victim, &target).unwrap();
    write_bytes(&target, b"picture").unwrap();
    assert_eq!(std::fs::read(&victim).unwrap(), b"input");
    assert_eq!(std::fs::read(&target).unwrap(), b"picture");
    std::fs::remove_dir_all(&dir).unwrap();
}
