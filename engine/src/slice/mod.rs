//! Slice extraction: the walks that interpolate the stored spectrum on a
//! plane through the origin. [`exact`] sums tap by tap in the core's order
//! (its values bit for bit); [`strip`] and [`column`] factor the sums along
//! the rows or the axis the slice contains; [`adaptive`] is the paper's §4.

/// `$body` with the constant `$w` set to the filter width `$width`: 1 to 5
/// as they are, any other as [`fvr_core::filter::MAX_WIDTH`]. The widths
/// the walks are compiled for, listed once.
macro_rules! for_width {
    ($width:expr, $w:ident => $body:expr) => {
        for_width!(@arms $width, $w, $body, 1 2 3 4 5)
    };
    (@arms $width:expr, $w:ident, $body:expr, $($n:literal)*) => {
        match $width {
            $($n => {
                const $w: usize = $n;
                $body
            })*
            _ => {
                const $w: usize = fvr_core::filter::MAX_WIDTH;
                $body
            }
        }
    };
}

pub mod adaptive;
pub mod column;
pub mod exact;
mod prefetch;
mod runs;
pub mod strip;
mod taps;
