//! Views of a prepared spectrum: plain X-ray views ([`view`]), batches of
//! views ([`batch`]), adaptive views ([`adaptive`]), depth-cued and shaded
//! scenes ([`shaded`]) and turntables ([`turntable`]).

pub mod adaptive;
pub mod batch;
pub mod shaded;
pub mod turntable;
pub mod view;
