//! The measuring commands: accuracy against exact line integrals, storage
//! precision, growth with the volume's side and the speed–accuracy trade.

pub mod accuracy;
pub mod adaptive_table;
pub mod growth;
pub mod precision;
pub mod timing;
pub mod trade;
