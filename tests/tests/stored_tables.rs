//! Tables stored at build time (e.g. in a firmware's flash) rebuild the same
//! objects as computing them on the target.

use fvr_core::filter::{Filter, FilterKind, KernelTable};
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
    let short = &good[..good.len() - 1];
    assert!(matches!(
        KernelTable::from_values(filter, short),
        Err(Error::LengthMismatch { what: "kernel table", expected, got })
            if expected == good.len() && got == good.len() - 1
    ));
    // A kb4 table does not serve a kb3 filter.
    let kb4 = KernelTable::<f32>::new(Filter::new(FilterKind::Kb4, 1).unwrap());
    assert!(KernelTable::from_values(filter, kb4.values()).is_err());
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        let mut values = good.clone();
        values[700] = bad;
        let err = KernelTable::from_values(filter, &values).unwrap_err();
        assert_eq!(
            err,
            Error::NonFiniteTableEntry {
                what: "kernel table",
                index: 700
            }
        );
        assert_eq!(err.to_string(), "kernel table entry 700 is NaN or infinite");
    }
}
