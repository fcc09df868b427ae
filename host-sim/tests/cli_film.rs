//! `--display film`: a render's PNG shows `1 − exp(−k·p)` of its line
//! integrals (a radiograph's look), ordered as the integrals are, on
//! [0, 1]; the NRRD keeps the integrals; colour images, bad gains and
//! turntables are one line, exit 2, nothing written.

mod common;
use common::{assert_error, fvr_line, fvr_ok, grey_png, temp_dir};

/// The f32 samples of a NRRD fvr wrote (raw, little-endian).
fn samples(path: &std::path::Path) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    let at = bytes.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    bytes[at..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

#[test]
fn film_orders_pixels_as_the_integrals_and_keeps_the_nrrd() {
    let dir = temp_dir("film");
    let view = "render sphere@32 --dir 1,0.3,0.2";
    fvr_ok(&format!("{view} --out p.nrrd --quiet"), &dir);
    fvr_ok(&format!("{view} --display film --out q.nrrd --quiet"), &dir);
    assert_eq!(
        std::fs::read(dir.join("p.nrrd")).unwrap(),
        std::fs::read(dir.join("q.nrrd")).unwrap(),
        "an NRRD keeps the line integrals"
    );
    fvr_ok(&format!("{view} --out lin.png --quiet"), &dir);
    fvr_ok(
        &format!("{view} --display film --out film.png --quiet"),
        &dir,
    );
    let p = samples(&dir.join("p.nrrd"));
    let (_, lin) = grey_png(&dir.join("lin.png"));
    let (_, film) = grey_png(&dir.join("film.png"));
    assert_eq!(film.len(), p.len());
    assert_ne!(film, lin, "film looks different from linear");
    // Monotonic in the integrals: a pixel with a clearly larger integral is
    // never darker (8-bit rounding aside).
    let max = p.iter().copied().fold(0.0f32, f32::max);
    for i in 0..p.len() {
        for j in (0..p.len()).step_by(7) {
            if p[i] > p[j] + 0.02 * max {
                assert!(
                    film[i] + 1 >= film[j],
                    "pixel {i} ({}) vs {j} ({})",
                    p[i],
                    p[j]
                );
            }
        }
    }
    // On [0, 1]: nothing in the way is black, the longest paths are near
    // white (k = 3 / p99: 95% attenuation), and the film lifts the thin
    // paths a linear window leaves dark.
    let brightest = p
        .iter()
        .enumerate()
        .fold(0, |b, (i, &v)| if v > p[b] { i } else { b });
    assert!(film[brightest] >= 240, "{}", film[brightest]);
    let empty = p.iter().position(|&v| v <= 0.0).unwrap();
    assert_eq!(film[empty], 0);
    let mid = (0..p.len())
        .filter(|&i| p[i] > 0.15 * max && p[i] < 0.35 * max)
        .collect::<Vec<_>>();
    assert!(!mid.is_empty());
    let mean = |img: &[u8]| mid.iter().map(|&i| img[i] as f64).sum::<f64>() / mid.len() as f64;
    assert!(
        mean(&film) > mean(&lin) + 20.0,
        "{} vs {}",
        mean(&film),
        mean(&lin)
    );
    // An explicit gain is used as given: a tiny one keeps everything dark.
    fvr_ok(
        &format!("{view} --display film:1e-6 --out dim.png --quiet"),
        &dir,
    );
    let (_, dim) = grey_png(&dir.join("dim.png"));
    assert!(dim.iter().all(|&v| v <= 1), "{:?}", dim.iter().max());
}

#[test]
fn film_refusals_are_one_line() {
    let dir = temp_dir("film-refused");
    for (line, needle) in [
        (
            "render sphere@16 --dir 1,0,0 --display film:0 --out a.png",
            "film:K needs a finite K > 0",
        ),
        (
            "render sphere@16 --dir 1,0,0 --display films --out a.png",
            "expected linear, film or film:K",
        ),
        (
            "render teapot@32 --dir 1,0,0 --light-ring 3 --display film --out a.png",
            "--display film shows the line integrals of a grey X-ray render",
        ),
        (
            "turntable sphere@16 --frames 4 --display film --out a.apng",
            "--display film is for fvr render",
        ),
    ] {
        let out = fvr_line(line, &dir);
        assert_error(&out, &[needle]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.lines().count(), 1, "{line}: {err}");
        assert!(
            !dir.join("a.png").exists() && !dir.join("a.apng").exists(),
            "{line}"
        );
    }
}
