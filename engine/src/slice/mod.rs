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
#[cfg(target_arch = "x86_64")]
mod f16c;
mod prefetch;
mod runs;
pub mod strip;
mod taps;

/// Whether this core has F16C and AVX and `S` and `T` are binary16 summed
/// in `f32`: the case the walks' lane sums ([`f16c`]) serve. Always
/// `false` off x86-64.
fn f16c_available<S: fvr_core::num::Sample, T: fvr_core::num::Real>() -> bool {
    #[cfg(target_arch = "x86_64")]
    return f16c::available::<S, T>();
    #[cfg(not(target_arch = "x86_64"))]
    false
}
