//! Tables stored at build time (e.g. in a firmware's flash) rebuild the same
//! objects as computing them on the target.

use fvr_core::filter::{DerivativeTable, Filter, FilterKind, KernelTable};
use fvr_core::Error;

#[test]
fn kernel_table_from_values_equals_the_computed_table_bit_for_bit() {
    for kind in FilterKind::ALL {
        for oversample in [1, 2] {
            let filter = Filter::new(kind, oversample).unwrap();
            let computed = KernelTable::<f32>::new(filter);
            assert_eq!(
                computed.values().len(),
                KernelTable::<f32>::len_for(&filter)
            );
            let stored = KernelTable::from_values(filter, computed.values()).unwrap();
            assert_eq!(stored.filter(), computed.filter());
            // Every lookup, on and between the table's grid points.
            let half_width = kind.width() as f32 / 2.0;
            for step in 0..=4096 {
                let t = half_width * (step as f32 / 4096.0) * 1.0001 - 0.0001;
                assert_eq!(
                    stored.eval(t).to_bits(),
                    computed.eval(t).to_bits(),
                    "{} σ={oversample} t={t}",
                    kind.name()
                );
            }
        }
    }
}

#[test]
fn kernel_table_from_values_rejects_wrong_lengths_and_non_finite_entries() {
    let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
    let good = KernelTable::<f32>::new(filter).values().to_vec();
    let kb4 = KernelTable::<f32>::new(Filter::new(FilterKind::Kb4, 1).unwrap());
    let refusals = Refusals {
        filter,
        good: &good,
        other_filter: kb4.values(),
        what: "kernel table",
        index: 700,
    };
    refusals.check(KernelTable::from_values);
}

#[test]
fn derivative_table_from_values_equals_the_computed_table_bit_for_bit() {
    for kind in FilterKind::ALL {
        if kind == FilterKind::Nearest {
            continue;
        }
        for oversample in [1, 2] {
            let filter = Filter::new(kind, oversample).unwrap();
            let computed = DerivativeTable::<f32>::new(filter).unwrap();
            assert_eq!(
                computed.values().len(),
                DerivativeTable::<f32>::len_for(&filter)
            );
            let stored = DerivativeTable::from_values(filter, computed.values()).unwrap();
            assert_eq!(stored.filter(), computed.filter());
            assert_eq!(stored.values(), computed.values());
            // Every lookup, on both sides of 0 (the table is odd) and between
            // the grid points, and the taps at fractional positions.
            let half_width = kind.width() as f32 / 2.0;
            for step in -4096..=4096 {
                let t = half_width * (step as f32 / 4096.0) * 1.0001;
                assert_eq!(
                    stored.eval(t).to_bits(),
                    computed.eval(t).to_bits(),
                    "{} σ={oversample} t={t}",
                    kind.name()
                );
            }
            for q in [-7.3f32, -0.5, 0.0, 0.25, 3.999, 12.5] {
                let (mut a, mut b) = ([0.0; 6], [0.0; 6]);
                assert_eq!(stored.taps(q, &mut a), computed.taps(q, &mut b));
                assert_eq!(a.map(f32::to_bits), b.map(f32::to_bits));
            }
        }
    }
}

#[test]
fn derivative_table_from_values_rejects_nearest_wrong_lengths_and_non_finite_entries() {
    let filter = Filter::new(FilterKind::Kb3, 1).unwrap();
    let good = DerivativeTable::<f32>::new(filter)
        .unwrap()
        .values()
        .to_vec();
    // Nearest neighbour has no derivative table, stored or computed.
    let nearest = Filter::new(FilterKind::Nearest, 1).unwrap();
    let nearest_len = DerivativeTable::<f32>::len_for(&nearest);
    assert_eq!(
        DerivativeTable::from_values(nearest, &vec![0.0f32; nearest_len]).unwrap_err(),
        Error::NoKernelDerivative
    );
    // A kb4 derivative table does not serve a kb3 filter.
    let kb4 = DerivativeTable::<f32>::new(Filter::new(FilterKind::Kb4, 1).unwrap()).unwrap();
    let refusals = Refusals {
        filter,
        good: &good,
        other_filter: kb4.values(),
        what: "kernel derivative table",
        index: 1200,
    };
    refusals.check(DerivativeTable::from_values);
}

/// What a table's `from_values` must refuse: `good` shortened by one, the
/// table of another filter, and a NaN or infinity at `index`, each named
/// `what`.
struct Refusals<'a> {
    filter: Filter,
    good: &'a [f32],
    other_filter: &'a [f32],
    what: &'static str,
    index: usize,
}

impl Refusals<'_> {
    fn check<T: std::fmt::Debug>(&self, from_values: impl Fn(Filter, &[f32]) -> Result<T, Error>) {
        let (filter, good, what) = (self.filter, self.good, self.what);
        let short = &good[..good.len() - 1];
        assert!(matches!(
            from_values(filter, short),
            Err(Error::LengthMismatch { what: w, expected, got })
                if w == what && expected == good.len() && got == good.len() - 1
        ));
        assert!(from_values(filter, self.other_filter).is_err());
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut values = good.to_vec();
            values[self.index] = bad;
            let err = from_values(filter, &values).unwrap_err();
            assert_eq!(
                err,
                Error::NonFiniteTableEntry {
                    what,
                    index: self.index
                }
            );
            assert_eq!(
                err.to_string(),
                format!("{what} entry {} is NaN or infinite", self.index)
            );
        }
    }
}
