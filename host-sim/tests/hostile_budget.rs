//! Hostile requests against the memory budget and the transform size: the
//! whole job (volume, spectra, images, frames) is checked before decoding,
//! and a volume's shape cannot force a huge cubic transform.

mod common;

use std::io::Write;
use std::path::Path;

use common::{assert_error, assert_ok, fvr_line, fvr_ok, temp_dir};
use fvr_host::image::output::{ApngStream, Style};

/// A NRRD header declaring `sizes` of uchar, followed by `data` (which may
/// be far shorter than declared: a refusal must come before reading it).
fn nrrd_header(dir: &Path, name: &str, sizes: &str, encoding: &str, data: &[u8]) {
    let mut f = std::fs::File::create(dir.join(name)).unwrap();
    write!(
        f,
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: {sizes}\nencoding: {encoding}\n\n"
    )
    .unwrap();
    f.write_all(data).unwrap();
}

#[test]
fn a_thin_volume_is_not_padded_into_a_huge_cube() {
    let dir = temp_dir("budget-thin");
    nrrd_header(&dir, "line.nrrd", "1000 1 1", "raw", &[7u8; 1000]);
    for cmd in [
        "render line.nrrd --dir 1,0,0 --out x.png",
        "turntable line.nrrd --frames 2 --out t.apng",
    ] {
        let out = fvr_line(cmd, &dir);
        assert_error(&out, &["1000x1x1", "1024^3", "at most 256"]);
    }
    // A slab within the ratio renders.
    nrrd_header(&dir, "slab.nrrd", "32 32 2", "raw", &[1u8; 2048]);
    fvr_ok("render slab.nrrd --dir 0,0,1 --up 0,1,0 --out s.png", &dir);
}

/// The gzip data is the 10-byte header of a stream declared to inflate to
/// 128 MiB; the
/// refusal names the budget, so it came before any decompression (reading
/// would have failed as a truncated stream instead).
#[test]
fn the_whole_job_is_checked_before_decompressing() {
    let dir = temp_dir("budget-gzip");
    nrrd_header(
        &dir,
        "bomb.nrrd",
        "512 512 512",
        "gzip",
        &[0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3],
    );
    let out = fvr_line(
        "--max-memory 700M render bomb.nrrd --dir 1,0,0 --out x.png",
        &dir,
    );
    assert_error(&out, &["this job needs about", "spectrum", "--max-memory"]);
    assert!(!dir.join("x.png").exists());
    // Decoded, the volume is 512 MiB: fits alone, but not with its spectrum
    // (256 MiB at f16); nor with a second image to compare it against.
    assert_error(&out, &["decoded volume 512.0 MiB", "spectrum 256.0 MiB"]);
    let out = fvr_line("--max-memory 700M compare bomb.nrrd bomb.nrrd", &dir);
    assert_error(&out, &["second image 512.0 MiB"]);
}

/// The same under `ulimit -v 3000000` (about 2.9 GiB), in a child process:
/// a 1200³ volume (6.4 GiB decoded) is refused by the address-space limit
/// before its 10-byte gzip stream is touched.
#[test]
fn the_address_space_limit_bounds_a_gzip_bomb() {
    let dir = temp_dir("budget-rlimit");
    nrrd_header(
        &dir,
        "bomb.nrrd",
        "1200 1200 1200",
        "gzip",
        &[0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3],
    );
    for cmd in [
        "render bomb.nrrd --dir 1,0,0 --out x.png",
        "compare bomb.nrrd bomb.nrrd",
    ] {
        let out = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!(
                "ulimit -v 3000000 && exec '{}' {cmd}",
                env!("CARGO_BIN_EXE_fvr")
            ))
            .current_dir(&dir)
            .output()
            .expect("sh runs");
        assert_error(&out, &["address-space limit"]);
    }
}

#[test]
fn compare_plans_for_both_images() {
    let dir = temp_dir("budget-compare");
    // 256³ uchar: 64 MiB decoded each; one fits 100 MiB, two do not.
    nrrd_header(&dir, "a.nrrd", "256 256 256", "raw", &[]);
    let out = fvr_line("--max-memory 100M compare a.nrrd a.nrrd", &dir);
    assert_error(&out, &["second image", "compare smaller images"]);
}

/// Lights add a `|∇f|` spectrum and a gradient volume: the same render that
/// fits without them is refused with them, by the sum.
#[test]
fn spectra_of_a_scene_are_summed() {
    let dir = temp_dir("budget-scene");
    let base = "--max-memory 120M render sphere@128 --oversample 2 --dir 1,0,0 --out x.png";
    fvr_ok(base, &dir);
    let out = fvr_line(&format!("{base} --light 0,1,0:1"), &dir);
    assert_error(&out, &["this job needs about", "spectrum", "--max-memory"]);
}

fn apng_frames(bytes: &[u8]) -> u32 {
    let at = bytes
        .windows(4)
        .position(|w| w == b"acTL")
        .expect("an acTL chunk");
    u32::from_be_bytes(bytes[at + 4..at + 8].try_into().unwrap())
}

/// 2100 frames of 128² in f64 are 275 MB: more than the turntable keeps, so
/// the window comes from sampled frames and every frame is encoded as it
/// is rendered. The animation is whole and no temporary file is left.
#[test]
fn long_turntables_stream_their_frames() {
    let dir = temp_dir("budget-stream");
    let out = fvr_line(
        "turntable sphere@128 --frames 2100 --out spin.apng --quiet",
        &dir,
    );
    assert_ok(&out);
    let bytes = std::fs::read(dir.join("spin.apng")).unwrap();
    assert_eq!(apng_frames(&bytes), 2100);
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name())
        .collect();
    assert_eq!(left, ["spin.apng"], "nothing beside the animation");
}

#[test]
fn an_unfinished_animation_leaves_nothing_behind() {
    let dir = temp_dir("budget-partial");
    let path = dir.join("a.apng");
    std::fs::write(&path, b"the previous animation").unwrap();
    let style = Style::default();
    {
        let mut s = ApngStream::create(&path, (4, 2), 2, 10, &style, (0.0, 1.0), false).unwrap();
        s.push(&[0.5; 8]).unwrap();
        assert!(s.push(&[0.5; 7]).is_err(), "a frame of the wrong size");
        // Dropped after one of two frames.
    }
    let mut s = ApngStream::create(&path, (4, 2), 2, 10, &style, (0.0, 1.0), false).unwrap();
    s.push(&[0.5; 8]).unwrap();
    let e = s.finish().unwrap_err();
    assert!(e.contains("1 frames were never written"), "{e}");
    assert_eq!(std::fs::read(&path).unwrap(), b"the previous animation");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    let mut s = ApngStream::create(&path, (4, 2), 1, 10, &style, (0.0, 1.0), false).unwrap();
    s.push(&[0.25; 8]).unwrap();
    assert!(s.push(&[0.25; 8]).is_err(), "more frames than declared");
    s.finish().unwrap();
    assert_eq!(apng_frames(&std::fs::read(&path).unwrap()), 1);
}
