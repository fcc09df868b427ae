//! Slice extraction: the walks that interpolate the stored spectrum on a
//! plane through the origin. [`exact`] sums tap by tap in the core's order
//! (its values bit for bit); [`strip`] and [`column`] factor the sums along
//! the rows or the axis the slice contains; [`adaptive`] is the paper's §4.

pub mod adaptive;
pub mod column;
pub mod exact;
mod prefetch;
mod runs;
pub mod strip;
mod taps;
