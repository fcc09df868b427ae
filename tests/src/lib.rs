//! Cross-crate integration tests live in `tests/tests/`; this library holds
//! the setup they share.

use fvr_core::filter::{Filter, FilterKind};
use fvr_engine::dht::real::FftReal;
use fvr_engine::dht::store::StoreFormat;
use fvr_engine::spectrum::OwnedSpectrum;
use fvr_engine::volume::phantom::{sample, GaussianMixture};

/// A random Gaussian mixture (`GaussianMixture::random(seed, n, count)`)
/// sampled on `dims`, prepared for `kind` at `oversample` in storage `S`
/// with arithmetic `T`; with the filter.
pub fn mixture_spectrum<S: StoreFormat, T: FftReal>(
    (seed, n, count): (u64, usize, usize),
    dims: [usize; 3],
    kind: FilterKind,
    oversample: u32,
) -> (OwnedSpectrum<S>, Filter) {
    let volume = sample(&GaussianMixture::random(seed, n, count), dims);
    let filter = Filter::new(kind, oversample).unwrap();
    let spec = OwnedSpectrum::<S>::prepare::<T>(&volume, filter).unwrap();
    (spec, filter)
}

/// `let` bindings of twiddle tables serving lengths up to `n`, one per
/// arithmetic type: `twiddles!(n; tw64: f64, tw32: f32)`.
#[macro_export]
macro_rules! twiddles {
    ($n:expr; $($name:ident: $t:ty),+) => {
        $(
            let mut $name = vec![<$t>::default(); ::fvr_core::dht::Twiddles::<$t>::buffer_len($n)];
            let $name = ::fvr_core::dht::Twiddles::new(&mut $name, $n).unwrap();
        )+
    };
}

/// Knuth's MMIX linear congruential generator: a fixed-seed stream of
/// 64-bit states for test data.
#[derive(Clone, Debug)]
pub struct Lcg(pub u64);

impl Lcg {
    /// The next state.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0
    }
}

/// `scene` with one more light (towards `towards`, of `color`).
pub fn with_light(
    mut scene: fvr_core::shading::Scene,
    towards: [f64; 3],
    color: [f64; 3],
) -> fvr_core::shading::Scene {
    scene
        .add_light(fvr_core::shading::Light { towards, color })
        .unwrap();
    scene
}
