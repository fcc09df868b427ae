// The page: volumes in, trackball and wheel, previews while dragging and
// full quality at rest, window/level, options, timing, PNG out. All the
// engine's work happens in the worker (the same module, started again as a
// Web Worker); this side only asks for views and draws them.
//
// Volumes come from the server the page was loaded from (`fvr view`):
// GET /info names the volume it serves, GET /volume sends it, GET
// /volume?spec=NAME a built-in data set or phantom, and POST /convert?name=F
// reads a dropped file with the project's readers, all in the wire format
// (web/src/wire.rs). `window.fvr` is the hook scripts/web-test.py drives.

const MAX_VOXELS = 2 ** 27; // as web/src/wire.rs
const REST_MS = 150; // full quality once the pointer rests this long

function startPage(moduleUrl) {
  const $ = (id) => document.getElementById(id);
  const canvas = $('view');
  const params = new URLSearchParams(location.search);
  const vec = (s, d) => (s ? s.split(',').map(Number) : d);
  // brainsmall's face looks down -x with the top of the head at -y: a
  // three-quarter view of it by default (?dir=X,Y,Z&up=X,Y,Z to change).
  const camera = new Camera(vec(params.get('dir'), [1, 0, 0.6]), vec(params.get('up'), [0, -1, 0]));
  const worker = new Worker(moduleUrl, { type: 'module' });

  const st = {
    name: null, info: null, plan: null, prepared: false, zoom: 1,
    window: null, image: null, fullMs: null, previewMs: null,
    inFlight: false, wanted: null, nextId: 1, busy: false, lastFull: null,
  };
  let firstView;
  const firstViewDone = new Promise((r) => (firstView = r));
  const replies = new Map();
  const shown = []; // every image drawn: level, size, brightest value

  // ---------- messages and progress ----------
  function say(text, ok = false) {
    const m = $('message');
    m.textContent = text ? text.split('\n')[0] : '';
    m.className = ok ? 'ok' : '';
  }
  function progress(stage, fraction) {
    const p = $('progress');
    $('stage').textContent = stage || '';
    p.style.visibility = stage ? 'visible' : 'hidden';
    p.className = fraction == null && stage ? 'busy' : '';
    p.firstElementChild.style.width = fraction == null ? '' : `${Math.round(100 * fraction)}%`;
    if (fraction == null && !stage) p.firstElementChild.style.width = '0';
  }
  function ask(msg, transfer = []) {
    return new Promise((resolve, reject) => {
      replies.set(msg.op, { resolve, reject });
      worker.postMessage(msg, transfer);
    });
  }
  worker.onmessage = (e) => {
    const m = e.data;
    if (m.op === 'render') return onImage(m);
    const r = replies.get(m.op);
    if (m.op === 'boot') return say(m.message);
    replies.delete(m.op);
    if (r) (m.ok ? r.resolve : r.reject)(m.ok ? m : new Error(m.message));
  };
  worker.onerror = (e) => say('the renderer could not start: ' + e.message);

  // ---------- opening volumes ----------
  async function download(response, label) {
    if (!response.ok) throw new Error((await response.text()) || `${label}: HTTP ${response.status}`);
    const total = Number(response.headers.get('content-length')) || 0;
    const reader = response.body.getReader();
    let buf = null;
    let got = 0;
    for (;;) {
      const { done, value } = await reader.read();
      if (done) break;
      if (!buf) {
        checkHeader(value);
        try {
          buf = new Uint8Array(Math.max(total, value.length));
        } catch {
          throw new Error(`${label} (${total} bytes) is too large for the browser's memory`);
        }
      }
      if (got + value.length > buf.length) {
        const grown = new Uint8Array(2 * (got + value.length));
        grown.set(buf.subarray(0, got));
        buf = grown;
      }
      buf.set(value, got);
      got += value.length;
      progress(`loading ${label}`, total ? got / total : null);
    }
    if (!buf) throw new Error(`${label}: empty response`);
    return buf.buffer.slice(0, got);
  }
  function checkHeader(bytes) {
    if (bytes.length < 20 || new TextDecoder().decode(bytes.subarray(0, 8)) !== 'FVRVOL1\n') return;
    const v = new DataView(bytes.buffer, bytes.byteOffset, 20);
    const dims = [v.getUint32(8, true), v.getUint32(12, true), v.getUint32(16, true)];
    if (dims[0] * dims[1] * dims[2] > MAX_VOXELS)
      throw new Error(`a ${dims.join('x')} volume is too large for the browser's memory (at most 512^3 voxels)`);
  }
  // Runs `work` with the viewer busy; its error is shown, and an option
  // changed meanwhile is applied after it.
  async function whileBusy(work) {
    st.busy = true;
    try {
      await work();
    } catch (e) {
      say(e.message);
    } finally {
      st.busy = false;
      progress(null);
      afterBusy();
    }
  }
  async function open(label, fetchIt) {
    if (st.busy) return say('still preparing the last volume; wait for it');
    // On an error before the new volume was accepted, the old one is still there.
    await whileBusy(async () => {
      say('');
      progress(`loading ${label}`, 0);
      const bytes = await download(await fetchIt(), label);
      progress(`reading ${label}`, null);
      const { info } = await ask({ op: 'load', bytes }, [bytes]);
      // The worker now holds the new volume: the old renderer is gone.
      st.prepared = false;
      st.name = label;
      st.info = info;
      st.window = null;
      st.zoom = 1;
      await prepare();
    });
  }
  async function prepare() {
    if (!st.info) return;
    st.prepared = false;
    progress(`preparing ${st.name}: planning, premultiplying and transforming (once per volume)`, null);
    const options = { accuracy: Number($('accuracy').value), cue: Number($('cue').value), lights: $('lights').checked };
    const { plan } = await ask({ op: 'prepare', ...options });
    st.plan = plan;
    st.shaded = options.cue !== 0 || options.lights;
    st.prepared = true;
    canvas.width = canvas.height = plan.side;
    say(plan.warnings.length ? plan.warnings[0] : `${st.name} ready`, !plan.warnings.length);
    showInfo();
    request(0);
  }
  const openSpec = (spec, label) => open(label || spec, () => fetch(spec ? `volume?spec=${encodeURIComponent(spec)}` : 'volume'));
  async function openFile(file) {
    const head = new Uint8Array(await file.slice(0, 8).arrayBuffer());
    if (new TextDecoder().decode(head) === 'FVRVOL1\n') return open(file.name, async () => new Response(file));
    return open(file.name, async () => {
      const r = await fetch(`convert?name=${encodeURIComponent(file.name)}`, { method: 'POST', body: file });
      if (r.status === 404 || r.status === 405)
        throw new Error(`${file.name}: opening files needs the page served by \`fvr view\``);
      return r;
    });
  }

  // ---------- views ----------
  function request(level) {
    if (!st.prepared) return;
    st.wanted = { op: 'render', dir: camera.dir, up: camera.up, zoom: st.zoom, level };
    pump();
  }
  function pump() {
    if (st.inFlight || !st.wanted) return;
    const m = { ...st.wanted, id: st.nextId++ };
    st.wanted = null;
    st.inFlight = true;
    worker.postMessage(m);
  }
  function onImage(m) {
    st.inFlight = false;
    if (!m.ok) {
      say(m.message);
      if (m.lost) st.prepared = false;
    } else {
      st.image = m.image;
      if (m.level === 0) {
        st.fullMs = m.image.ms;
        st.lastFull = m.image;
        if (!st.window) st.window = autoWindow(m.image);
      } else st.previewMs = m.image.ms;
      if (!st.window) st.window = autoWindow(m.image);
      st.shownLevel = m.level;
      let max = -Infinity;
      for (const v of m.image.data) if (v > max) max = v;
      shown.push({ level: m.level, w: m.image.w, h: m.image.h, max });
      if (shown.length > 1000) shown.splice(0, 500);
      draw();
      showInfo();
      if (m.level === 0 && !st.wanted) firstView(true);
    }
    pump();
  }
  function autoWindow(img) {
    let lo = Infinity;
    let hi = -Infinity;
    for (const v of img.data) {
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
    if (img.channels === 3) lo = Math.min(lo, 0);
    return { lo, hi: hi > lo ? hi : lo + 1 };
  }
  const scratch = document.createElement('canvas');
  function draw() {
    const img = st.image;
    if (!img) return;
    scratch.width = img.w;
    scratch.height = img.h;
    const ctx = scratch.getContext('2d');
    const out = ctx.createImageData(img.w, img.h);
    const { lo, hi } = st.window;
    const k = 255 / (hi - lo);
    for (let p = 0; p < img.w * img.h; p++) {
      for (let c = 0; c < 3; c++) out.data[4 * p + c] = (img.data[p * img.channels + (img.channels === 3 ? c : 0)] - lo) * k;
      out.data[4 * p + 3] = 255;
    }
    ctx.putImageData(out, 0, 0);
    const view = canvas.getContext('2d');
    view.imageSmoothingEnabled = true;
    view.fillStyle = '#000';
    view.fillRect(0, 0, canvas.width, canvas.height);
    // Plain views are zoomed by the engine (a finer pixel); cued and lit
    // ones, which need pixels as large as voxels, are magnified here.
    const z = st.shaded ? st.zoom : 1;
    const sw = img.w / z;
    const sh = img.h / z;
    view.drawImage(scratch, (img.w - sw) / 2, (img.h - sh) / 2, sw, sh, 0, 0, canvas.width, canvas.height);
  }
  function showInfo() {
    const p = st.plan;
    const rows = [
      ['volume', st.name],
      ['dims', st.info && st.info.dims.join(' × ')],
      ['spacing', st.info && st.info.spacing.join(', ') + ' mm'],
      ['target', p && `${p.target_db} dB`],
      ['predicted', p && `${p.predicted_db.toFixed(1)} dB`],
      ['filter', p && p.filter],
      ['grid', p && `oversample ${p.grid} (${p.n}³ spectrum)`],
      ['precision', p && p.precision],
      ['image', p && `${p.side} × ${p.side}, pixel ${+p.pixel_mm.toFixed(4)} mm, zoom ${st.zoom.toFixed(2)}`],
      ['prepare', p && `${p.prepare_ms.toFixed(0)} ms`],
      ['full view', st.fullMs != null && `${st.fullMs.toFixed(1)} ms (${(1000 / st.fullMs).toFixed(0)} views/s)`],
      ['preview', st.previewMs != null && `${st.previewMs.toFixed(1)} ms (${(1000 / st.previewMs).toFixed(0)} views/s)`],
      ['shown', st.image && (st.shownLevel ? `preview level ${st.shownLevel}` : 'full quality')],
    ];
    $('info').innerHTML = '';
    for (const [k, v] of rows) {
      if (!v) continue;
      const tr = $('info').insertRow();
      tr.insertCell().textContent = k;
      tr.insertCell().textContent = v;
    }
  }

  // ---------- pointer, wheel, keys ----------
  let drag = null;
  let restTimer = 0;
  const toUnit = (e) => {
    const r = canvas.getBoundingClientRect();
    return [(2 * (e.clientX - r.left)) / r.width - 1, 1 - (2 * (e.clientY - r.top)) / r.height];
  };
  const previewLevel = () => Math.max(0, Math.min(4, Number($('level').value) | 0));
  function atRest() {
    clearTimeout(restTimer);
    restTimer = setTimeout(() => request(0), REST_MS);
  }
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => {
    drag = { button: e.button, at: toUnit(e), x: e.clientX, y: e.clientY };
    canvas.setPointerCapture(e.pointerId);
    canvas.classList.add('dragging');
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    if (drag.button === 2) {
      if (!st.window) return;
      // Right-drag: width grows to the right, the centre rises upwards.
      const { lo, hi } = st.window;
      const w = (hi - lo) * Math.exp(0.01 * (e.clientX - drag.x));
      const c = (hi + lo) / 2 - 0.005 * (hi - lo) * (e.clientY - drag.y);
      st.window = { lo: c - w / 2, hi: c + w / 2 };
      drag.x = e.clientX;
      drag.y = e.clientY;
      return draw();
    }
    const at = toUnit(e);
    camera.drag(drag.at[0], drag.at[1], at[0], at[1]);
    drag.at = at;
    request(previewLevel());
    atRest();
  });
  const release = () => {
    if (!drag) return;
    drag = null;
    canvas.classList.remove('dragging');
    atRest();
  };
  canvas.addEventListener('pointerup', release);
  canvas.addEventListener('pointercancel', release);
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    st.zoom = Math.min(16, Math.max(0.25, st.zoom * Math.exp(-0.0015 * e.deltaY)));
    request(previewLevel());
    atRest();
  }, { passive: false });
  const reset = () => {
    camera.reset();
    st.zoom = 1;
    st.window = st.lastFull ? null : st.window;
    request(0);
  };
  canvas.addEventListener('dblclick', reset);
  $('reset').onclick = reset;

  // ---------- controls ----------
  for (const b of document.querySelectorAll('#volumes button')) b.onclick = () => openSpec(b.dataset.spec);
  $('file').onchange = (e) => e.target.files[0] && openFile(e.target.files[0]);
  // An option changed while a preparation runs is applied after it.
  const reprepare = async () => {
    if (st.busy) return void (st.again = true);
    if (!st.info) return;
    await whileBusy(async () => {
      st.window = null;
      await prepare();
    });
  };
  function afterBusy() {
    if (st.again) {
      st.again = false;
      reprepare();
    }
  }
  for (const id of ['accuracy', 'cue', 'lights']) $(id).onchange = reprepare;
  $('save').onclick = () =>
    canvas.toBlob((blob) => {
      const a = document.createElement('a');
      a.href = URL.createObjectURL(blob);
      a.download = `fvr-${(st.name || 'view').replace(/[^\w.-]+/g, '_')}.png`;
      a.click();
      setTimeout(() => URL.revokeObjectURL(a.href), 1000);
    });
  const drop = $('drop');
  document.addEventListener('dragover', (e) => { e.preventDefault(); drop.classList.add('on'); });
  document.addEventListener('dragleave', (e) => { if (!e.relatedTarget) drop.classList.remove('on'); });
  document.addEventListener('drop', (e) => {
    e.preventDefault();
    drop.classList.remove('on');
    const f = e.dataTransfer.files[0];
    if (f) openFile(f);
  });

  // ---------- the test and benchmark hook ----------
  window.fvr = {
    firstView: firstViewDone,
    shown,
    state: () => ({ name: st.name, prepared: st.prepared, busy: st.busy, plan: st.plan, shownLevel: st.shownLevel,
      image: st.image && { w: st.image.w, h: st.image.h, channels: st.image.channels, ms: st.image.ms },
      message: $('message').textContent, dir: camera.dir, up: camera.up }),
    openSpec,
    // The full-quality image of a view, its f32 pixels in base64.
    async render(dir, up, level = 0) {
      camera.set(dir, up);
      st.zoom = 1;
      const m = await new Promise((resolve) => {
        const old = worker.onmessage;
        worker.onmessage = (e) => {
          if (e.data.op !== 'render' || e.data.id !== -1) return old(e);
          worker.onmessage = old;
          resolve(e.data);
        };
        worker.postMessage({ op: 'render', id: -1, dir: camera.dir, up: camera.up, zoom: 1, level });
      });
      if (!m.ok) throw new Error(m.message);
      const bytes = new Uint8Array(m.image.data.buffer);
      let s = '';
      for (let i = 0; i < bytes.length; i += 0x8000) s += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
      return { w: m.image.w, h: m.image.h, channels: m.image.channels, ms: m.image.ms, b64: btoa(s) };
    },
    bench: (level, count) => ask({ op: 'bench', dir: [0.3, 1, -0.45], up: [0, 0, 1], zoom: 1, level, count }),
  };

  // ---------- first volume ----------
  (async () => {
    const spec = params.get('volume');
    if (spec) return openSpec(spec);
    try {
      const r = await fetch('info');
      const served = r.ok && (await r.json()).volume;
      if (served) return openSpec(null, served);
    } catch {
      // No server behind the page: the buttons still work where it serves.
    }
    say('choose a volume, or drop a NRRD or NIfTI file', true);
  })();
}
