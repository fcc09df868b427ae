//! The browser viewer's engine side (issue 40): `fvr-engine` compiled to
//! `wasm32-unknown-unknown` with SIMD128 and no threads (rayon's global
//! pool falls back to the calling thread there).
//!
//! - [`wire`]: the volume format `fvr view` serves and the page hands over;
//! - [`session`]: one volume, its plan and preparation, and its views;
//! - `exports` (wasm only): the plain `extern "C"` functions the page's
//!   JavaScript calls, over an inbox and an outbox in linear memory.
//!
//! `scripts/web.sh` builds the `.wasm` and copies the page (web/page/)
//! beside it into web/dist/.

#[cfg(target_arch = "wasm32")]
mod exports;
pub mod session;
pub mod wire;
