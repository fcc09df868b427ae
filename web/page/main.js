// fvr.js's entry: the page, or, started again as a module Web Worker by
// the page, the worker that holds the WebAssembly engine.
if (typeof document === 'undefined') startWorker(self, new URL('fvr_web.wasm', import.meta.url));
else startPage(import.meta.url);
