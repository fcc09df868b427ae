//! fvr-core on a Cortex-M4F: the firmware's portable parts and, for
//! `target_os = "none"`, its device runtime.
//!
//! The scene ([`scene`]) is an analytic phantom whose f16 spectra (density,
//! and `|∇f|` for shaded frames) `build.rs` makes on the host, with the
//! core, and keeps in flash with the kernel and kernel-derivative tables
//! ([`stored`]). On the device a plain frame is rendered twice, once by
//! `fvr_core::render::render` and once stage by stage to count instructions;
//! a depth-cued or shaded frame once, by
//! `fvr_core::render::render` with a scene ([`frame`]). The image (grey or
//! RGB) goes back to the host as a NRRD over semihosting ([`nrrd`]) and to
//! a display through an `embedded-hal` 1.0 `SpiDevice` ([`display`]), whose
//! bytes a capture bus ([`capture`]) records for the host to check.
//!
//! Everything but `device` builds and is tested on the host; `device` needs
//! `thumbv7em-none-eabihf` (`bash scripts/firmware.sh`).
#![cfg_attr(not(test), no_std)]

pub mod capture;
pub mod display;
pub mod fixed_view;
pub mod frame;
pub mod nrrd;
pub mod prep_volume;
pub mod prepare;
pub mod scene;
pub mod stored;
pub mod stored_q15;

#[cfg(target_os = "none")]
pub mod device;
#[cfg(all(target_os = "none", target_abi = "eabihf"))]
pub mod prepare_device;
