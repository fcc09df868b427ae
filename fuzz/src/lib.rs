//! What every volume-reader fuzz target asserts of an accepted file.

use fvr_engine::volume::Volume;

/// An accepted file gives a consistent volume: as many samples as the
/// sizes claim, finite samples, and finite, positive spacing. A refused file
/// (any error) is fine.
pub fn check_volume<E>(read: Result<Volume, E>) {
    if let Ok(volume) = read {
        assert_eq!(volume.data.len(), volume.dims.iter().product::<usize>());
        assert!(volume.data.iter().all(|v| v.is_finite()));
        assert!(volume.spacing.iter().all(|s| s.is_finite() && *s > 0.0));
    }
}
