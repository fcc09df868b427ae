//! Views of a prepared spectrum: plain X-ray views ([`view`]), batches of
//! views ([`batch`]), adaptive views ([`adaptive`]), depth-cued and shaded
//! scenes ([`shaded`]), turntables ([`turntable`]) and magnified views
//! ([`zoom`]).

pub mod adaptive;
pub mod batch;
pub mod shaded;
pub mod turntable;
pub mod view;
pub mod zoom;
