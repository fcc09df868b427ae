//! Slice extraction: the walks that interpolate the stored spectrum on a
//! plane through the origin. [`exact`] sums tap by tap in the core's order
//! (its values bit for bit); [`strip`] and [`column`] factor the sums along
//! the rows or the axis the slice contains; [`adaptive`] is the paper's §4.

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
