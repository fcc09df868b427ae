//! The plain exports the page's JavaScript calls (no wasm-bindgen: the
//! glue is the few lines in web/page/fvr.js, and CI needs no extra tool).
//!
//! Data crosses through two byte buffers in linear memory: the page asks
//! for an inbox of some length ([`fvr_inbox`]), writes into it and calls a
//! function that reads it; every function leaves its answer in the outbox
//! ([`fvr_outbox_ptr`], [`fvr_outbox_len`]): a JSON object, an error line, or
//! an image. Calls return 0 on success and 1 with the error line in the
//! outbox. Nothing here dereferences a pointer: the page reads and writes
//! the buffers through the module's memory; `#[no_mangle]` is the only
//! reason this file allows `unsafe_code`.
#![allow(unsafe_code)]

use std::cell::RefCell;

use fvr_core::geometry::View;

use crate::session::{Ask, Cue, Options, Session};
use crate::wire;

/// The engine's memory budget in the browser: a wasm32 module addresses
/// 4 GiB at most, and browsers grant less; 2 GiB leaves room for the page.
const MAX_MEMORY: u64 = 2 << 30;

#[derive(Default)]
struct State {
    session: Session,
    inbox: Vec<u8>,
    outbox: Vec<u8>,
}

thread_local! {
    static STATE: RefCell<State> = RefCell::new(State::default());
}

fn with<R>(f: impl FnOnce(&mut State) -> R) -> R {
    STATE.with(|s| f(&mut s.borrow_mut()))
}

/// Put `result` in the outbox: the text on success (0), the error line on
/// failure (1).
fn answer(state: &mut State, result: Result<Vec<u8>, String>) -> u32 {
    match result {
        Ok(bytes) => {
            state.outbox = bytes;
            0
        }
        Err(e) => {
            state.outbox = e.replace('\n', " ").into_bytes();
            1
        }
    }
}

/// Make the inbox `len` bytes long and return its address, or 0 when the
/// memory cannot grow that far.
#[no_mangle]
pub extern "C" fn fvr_inbox(len: usize) -> usize {
    fvr_engine::memory::set_max_memory(MAX_MEMORY);
    with(|s| {
        s.inbox = Vec::new();
        if s.inbox.try_reserve_exact(len).is_err() {
            return 0;
        }
        s.inbox.resize(len, 0);
        s.inbox.as_mut_ptr() as usize
    })
}

/// The outbox's address.
#[no_mangle]
pub extern "C" fn fvr_outbox_ptr() -> usize {
    with(|s| s.outbox.as_ptr() as usize)
}

/// The outbox's length in bytes.
#[no_mangle]
pub extern "C" fn fvr_outbox_len() -> usize {
    with(|s| s.outbox.len())
}

/// Decode the inbox as a wire-format volume ([`wire`]) and hold it;
/// the outbox gets `{"dims":[..],"spacing":[..]}`.
#[no_mangle]
pub extern "C" fn fvr_load() -> u32 {
    with(|s| {
        let inbox = std::mem::take(&mut s.inbox);
        let result = wire::decode(&inbox).map(|v| {
            let json = format!(
                "{{\"dims\":[{},{},{}],\"spacing\":[{},{},{}]}}",
                v.dims[0], v.dims[1], v.dims[2], v.spacing[0], v.spacing[1], v.spacing[2]
            );
            s.session.set_volume(v);
            json.into_bytes()
        });
        drop(inbox);
        answer(s, result)
    })
}

/// Plan and prepare the volume held: `accuracy_db` the target, `cue` 0
/// none, 1 linear, 2 sine, `lights` 0 or 1. The outbox gets the plan as
/// JSON: filter, grid, precision, predicted dB, spectrum side, image side
/// and the engine's warnings.
#[no_mangle]
pub extern "C" fn fvr_prepare(accuracy_db: f64, cue: u32, lights: u32) -> u32 {
    with(|s| {
        let cue = match cue {
            0 => Cue::None,
            1 => Cue::Linear,
            _ => Cue::Sine,
        };
        let options = Options {
            accuracy_db,
            cue,
            lights: lights != 0,
        };
        let result = s.session.prepare(options).and_then(|()| {
            let r = s.session.renderer().ok_or("no renderer")?;
            let plan = r.plan();
            let warnings: Vec<String> = r
                .warnings()
                .iter()
                .chain(&plan.warnings)
                .map(|w| format!("\"{}\"", w.replace('\\', "\\\\").replace('"', "\\\"")))
                .collect();
            Ok(format!(
                "{{\"filter\":\"{}\",\"grid\":\"{}\",\"precision\":\"{}\",\"predicted_db\":{:.2},\
                 \"target_db\":{},\"n\":{},\"side\":{},\"pixel_mm\":{},\"warnings\":[{}]}}",
                plan.filter.name(),
                plan.grid.name(),
                plan.precision,
                plan.prediction.db,
                accuracy_db,
                r.n(),
                r.default_side(),
                r.sampling().pixel_size(),
                warnings.join(",")
            )
            .into_bytes())
        });
        answer(s, result)
    })
}

/// Render the view along `(dx, dy, dz)` with up hint `(ux, uy, uz)`, at
/// `zoom` and preview `level`. The outbox gets width, height and channels
/// (u32, little-endian) then the pixels as f32, row 0 at the top, channels
/// interleaved.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub extern "C" fn fvr_render(
    dx: f64,
    dy: f64,
    dz: f64,
    ux: f64,
    uy: f64,
    uz: f64,
    zoom: f64,
    level: u32,
) -> u32 {
    with(|s| {
        let ask = Ask {
            view: View {
                dir: [dx, dy, dz],
                up: [ux, uy, uz],
            },
            zoom,
            level,
        };
        let result = s.session.render(&ask).map(|image| {
            let mut out = Vec::with_capacity(12 + 4 * image.data.len());
            for v in [image.width, image.height, image.channels] {
                out.extend_from_slice(&(v as u32).to_le_bytes());
            }
            for &v in &image.data {
                out.extend_from_slice(&(v as f32).to_le_bytes());
            }
            out
        });
        answer(s, result)
    })
}
