//! A DICOM series' `ImageOrientationPatient` and first
//! `ImagePositionPatient` become the volume's orientation, from LPS to RAS,
//! with the slice axis along the normal the slices are sorted by.

use fvr_host::io::dicom::{assemble, parse_slice, CtSlice};

fn series(orientation: [f64; 6], positions: &[[f64; 3]]) -> fvr_engine::volume::Volume {
    let pixels = [0i16; 6];
    let slices = positions
        .iter()
        .enumerate()
        .map(|(k, &position)| {
            let bytes = CtSlice {
                instance: k as u32 + 1,
                position,
                orientation,
                ..CtSlice::axial([3, 2], &pixels)
            }
            .encode();
            parse_slice(&bytes).unwrap()
        })
        .collect();
    assemble(slices).unwrap()
}

#[test]
fn axial_series_in_ras() {
    // Rows run to the patient's left, columns posterior (LPS +x, +y), the
    // slices superior; given out of order.
    let v = series(
        [1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        &[[10.0, -20.0, 9.0], [10.0, -20.0, 5.0], [10.0, -20.0, 7.0]],
    );
    let o = v.orientation.expect("ImageOrientationPatient given");
    // Columns: i to the left (−R), j posterior (−A), k superior.
    assert_eq!(
        o.direction,
        [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]
    );
    // The lowest slice's position, LPS (10, −20, 5) in RAS.
    assert_eq!(o.origin, [-10.0, 20.0, 5.0]);
}

#[test]
fn coronal_series_in_ras() {
    // Rows to the left, columns inferior (LPS −z): the normal is LPS
    // (1,0,0)×(0,0,−1) = (0,1,0), posterior.
    let v = series(
        [1.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        &[[0.0, 3.0, 50.0], [0.0, 1.0, 50.0]],
    );
    let o = v.orientation.unwrap();
    assert_eq!(
        o.direction,
        [[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]]
    );
    assert_eq!(o.origin, [0.0, -1.0, 50.0]);
}
