//! Views of a prepared spectrum: plain X-ray views ([`view`]), adaptive
//! views ([`adaptive`]), depth-cued and shaded scenes ([`shaded`]) and
//! turntables ([`turntable`]).

pub mod adaptive;
pub mod shaded;
pub mod turntable;
pub mod view;
