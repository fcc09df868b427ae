// The Web Worker's half of fvr.js: it owns the WebAssembly module (the
// project's engine, web/src/exports.rs) so that preparing a volume, which
// takes seconds for 256^3, never freezes the page. Messages in:
//   {op: 'load', bytes}            a wire-format volume (web/src/wire.rs)
//   {op: 'prepare', accuracy, cue, lights}
//   {op: 'render', id, dir, up, zoom, level}
//   {op: 'bench', dir, up, zoom, level, count}
// and out: {op, ok, ...} answers, or {op, ok: false, message}.
// scripts/web.sh puts this file at the end of fvr.js (one JS module).

export function startWorker(scope, wasmUrl) {
  let wasm = null;
  const instantiate = async () => {
    const bytes = await (await fetch(wasmUrl)).arrayBuffer();
    const { instance } = await WebAssembly.instantiate(bytes, {});
    wasm = instance.exports;
  };
  let chain = instantiate();
  chain.catch((e) => scope.postMessage({ op: 'boot', ok: false, message: 'cannot start WebAssembly: ' + e.message }));

  const outbox = () => new Uint8Array(wasm.memory.buffer, wasm.fvr_outbox_ptr(), wasm.fvr_outbox_len());
  const text = () => new TextDecoder().decode(outbox());
  const call = (rc) => { if (rc !== 0) throw new Error(text()); };

  function render(m) {
    const t0 = performance.now();
    call(wasm.fvr_render(m.dir[0], m.dir[1], m.dir[2], m.up[0], m.up[1], m.up[2], m.zoom, m.level));
    const ms = performance.now() - t0;
    const out = outbox();
    const head = new Uint32Array(out.buffer.slice(out.byteOffset, out.byteOffset + 12));
    const data = new Float32Array(out.buffer.slice(out.byteOffset + 12, out.byteOffset + out.length));
    return { w: head[0], h: head[1], channels: head[2], data, ms };
  }

  const ops = {
    load(m) {
      const len = m.bytes.byteLength;
      const ptr = wasm.fvr_inbox(len);
      if (ptr === 0) throw new Error(`a ${len}-byte volume is too large for the browser's memory`);
      new Uint8Array(wasm.memory.buffer, ptr, len).set(new Uint8Array(m.bytes));
      call(wasm.fvr_load());
      return { info: JSON.parse(text()) };
    },
    prepare(m) {
      const t0 = performance.now();
      call(wasm.fvr_prepare(m.accuracy, m.cue, m.lights ? 1 : 0));
      const plan = JSON.parse(text());
      plan.prepare_ms = performance.now() - t0;
      return { plan };
    },
    render(m) {
      const image = render(m);
      return { id: m.id, level: m.level, image, transfer: [image.data.buffer] };
    },
    bench(m) {
      // m.count views turning about the up axis, timed here (no transfer).
      render(m);
      const t0 = performance.now();
      for (let i = 0; i < m.count; i++) {
        const a = (2 * Math.PI * i) / m.count;
        const d = [m.dir[0] * Math.cos(a) - m.dir[1] * Math.sin(a), m.dir[0] * Math.sin(a) + m.dir[1] * Math.cos(a), m.dir[2]];
        render({ ...m, dir: d });
      }
      const s = (performance.now() - t0) / 1000;
      return { views_per_s: m.count / s, ms_per_view: (1000 * s) / m.count };
    },
  };

  scope.onmessage = (e) => {
    const m = e.data;
    chain = chain.then(() => {
      try {
        const answer = ops[m.op](m);
        const transfer = answer.transfer || [];
        delete answer.transfer;
        scope.postMessage({ op: m.op, ok: true, ...answer }, transfer);
      } catch (err) {
        // A trap (a panic or an allocation the browser refused) leaves the
        // module unusable: start a fresh one and say the volume is gone.
        const trapped = err instanceof WebAssembly.RuntimeError;
        const message = trapped
          ? `the renderer ran out of memory or stopped (${err.message}); open a smaller volume`
          : err.message;
        scope.postMessage({ op: m.op, id: m.id, ok: false, lost: trapped, message });
        if (trapped) return instantiate();
      }
    });
  };
}
