//! The camera frame of a view: every vector that has a direction gets the
//! frame of that direction, and the rest are refused with a named error,
//! never a NaN frame (a NaN frame renders a NaN image).

use fvr_core::geometry::{too_short, View};
use fvr_core::Error;

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= 1e-12)
}

#[test]
fn tiny_and_huge_components_keep_their_direction() {
    let want = View::along([1.0, 0.5, 0.25]).frame().unwrap();
    for s in [1e-300, 1e-200, 1e200, 1e300, f64::MIN_POSITIVE * 4.0] {
        let got = View::along([s, s * 0.5, s * 0.25]).frame().unwrap();
        assert!(close(got.dir, want.dir), "scale {s:e}: {:?}", got.dir);
        assert!(close(got.right, want.right) && close(got.up, want.up));
    }
}

#[test]
fn subnormal_vectors_are_refused_before_they_become_nan() {
    let sub = [1e-320, 0.0, 0.0];
    assert!(too_short(sub) && too_short([0.0, -5e-324, 1e-310]));
    assert!(!too_short([0.0; 3]) && !too_short([f64::MIN_POSITIVE, 0.0, 0.0]));
    let short_dir = View {
        dir: sub,
        up: [0.0, 0.0, 1.0],
    };
    let short_up = View {
        dir: [1.0, 0.0, 0.0],
        up: [0.0, 0.0, 1e-320],
    };
    for view in [short_dir, short_up] {
        match view.frame() {
            Err(e @ Error::ShortViewVector { .. }) => {
                assert!(e.to_string().contains("too short to normalise"), "{e}")
            }
            other => panic!("{view:?}: {other:?}"),
        }
    }
    // A zero vector keeps its own error.
    assert!(matches!(
        View::along([0.0; 3]).frame(),
        Err(Error::ZeroViewVector { .. })
    ));
}
