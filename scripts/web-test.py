#!/usr/bin/env python3
"""The browser viewer in a real browser (issue 40): headless Chromium,
driven over the DevTools protocol on a pipe (--remote-debugging-pipe: no
port, no extra package), against `fvr view` on 127.0.0.1.

    python3 scripts/web-test.py --fvr target/release/fvr [--screenshot docs/web-brainsmall.png]
    python3 scripts/web-test.py --fvr target/release/fvr --bench

Test mode checks, each of which can fail:
  1. `fvr view brainsmall` prints its address; the page shows a first full
     view with no click;
  2. the page's image of a fixed view, read back as f32, against `fvr render`
     of the same view (`fvr compare --min-db FLOOR_DB`);
  3. a drag (real mouse events) draws preview-level images, then a full one;
  4. a non-volume file, a truncated NRRD and a volume too large for the
     browser each give a one-line message naming the problem, and the page
     still renders afterwards;
  5. Ctrl-C (SIGINT) stops `fvr view`.
Bench mode prints views/s for 128^3 and 256^3 at full quality and at the
drag preview level (one thread, in the worker), as a Markdown table.
"""

import argparse
import base64
import json
import os
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time

# The page's image against `fvr render`'s of the same view, in dB (SNR of
# the difference). Not bit for bit: the same Rust code, but rustfft's SIMD
# paths (AVX here, SIMD128 there) round differently, and a few f16 spectrum
# values round the other way. Measured 128.6 dB on 2026-11-28 (docs/web.md).
FLOOR_DB = 100.0
VIEW = ([0.3, 1.0, -0.45], [0.0, 0.0, 1.0])
CHROMIUM_FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-extensions", "--mute-audio", "--remote-debugging-pipe", "--window-size=1200,820",
]


def fail(msg):
    print(f"web-test: FAIL: {msg}", flush=True)
    sys.exit(1)


class Browser:
    """Chromium over --remote-debugging-pipe: JSON messages ending in NUL,
    commands on fd 3, answers and events on fd 4."""

    def __init__(self, binary, profile):
        to_child, self.w = os.pipe()
        self.r, from_child = os.pipe()

        def fds():
            # Out of the way first, so that neither end is clobbered
            # whichever numbers the pipes got; the fds kept open after this
            # are 3 and 4 (pass_fds), whatever they were in the parent.
            a, b = os.dup(to_child), os.dup(from_child)
            a, b = os.dup2(a, 100), os.dup2(b, 101)
            os.dup2(100, 3)
            os.dup2(101, 4)

        self.proc = subprocess.Popen(
            [binary, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", "about:blank"],
            preexec_fn=fds, pass_fds=(3, 4),
            stdout=subprocess.DEVNULL, stderr=open(f"{profile}.log", "w"))
        os.close(to_child)
        os.close(from_child)
        self.buf = b""
        self.next_id = 0
        self.session = None
        self.events = []

    def send(self, method, params=None, session=True, timeout=120):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session and self.session:
            msg["sessionId"] = self.session
        os.write(self.w, json.dumps(msg).encode() + b"\0")
        deadline = time.time() + timeout
        while True:
            reply = self.read(deadline, method)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    fail(f"{method}: {reply['error']}")
                return reply["result"]
            self.events.append(reply)

    def read(self, deadline, what):
        while b"\0" not in self.buf:
            left = deadline - time.time()
            if left <= 0 or not select.select([self.r], [], [], left)[0]:
                fail(f"Chromium did not answer {what} in time")
            chunk = os.read(self.r, 1 << 20)
            if not chunk:
                fail(f"Chromium exited during {what}")
            self.buf += chunk
        raw, self.buf = self.buf.split(b"\0", 1)
        return json.loads(raw)

    def open_page(self, url):
        target = self.send("Target.createTarget", {"url": "about:blank"}, session=False)
        self.session = self.send("Target.attachToTarget",
                                 {"targetId": target["targetId"], "flatten": True},
                                 session=False)["sessionId"]
        self.send("Emulation.setDeviceMetricsOverride",
                  {"width": 1200, "height": 820, "deviceScaleFactor": 1, "mobile": False})
        self.send("Page.navigate", {"url": url})

    def eval(self, expr, timeout=120):
        r = self.send("Runtime.evaluate", {"expression": expr, "awaitPromise": True,
                                           "returnByValue": True, "timeout": timeout * 1000},
                      timeout=timeout + 5)
        if "exceptionDetails" in r:
            fail(f"{expr[:60]}...: {r['exceptionDetails'].get('exception', {}).get('description', r['exceptionDetails'])}")
        return r["result"].get("value")

    def wait(self, expr, timeout=120, what=None):
        deadline = time.time() + timeout
        while time.time() < deadline:
            v = self.eval(expr, timeout)
            if v:
                return v
            time.sleep(0.1)
        fail(f"timed out waiting for {what or expr}")

    def close(self):
        try:
            self.send("Browser.close", session=False, timeout=10)
        except SystemExit:
            pass
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def serve(fvr, volume):
    p = subprocess.Popen([fvr, "--quiet", "view", volume], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    line = p.stdout.readline()
    if "http://127.0.0.1:" not in line:
        fail(f"fvr view printed no address: {line!r} {p.stderr.read() if p.poll() is not None else ''}")
    return p, line.split("at ")[1].split()[0]


def first_view(browser, name):
    browser.wait("typeof window.fvr === 'object'", 60, "the page's script")
    state = browser.eval("fvr.firstView.then(() => fvr.state())", 300)
    if state["name"] != name or state["shownLevel"] != 0 or not state["prepared"]:
        fail(f"first view of {name}: {state}")
    return state


def write_nrrd(path, w, h, raw):
    with open(path, "wb") as f:
        f.write(f"NRRD0004\ntype: float\ndimension: 2\nsizes: {w} {h}\nencoding: raw\n"
                f"endian: little\n\n".encode())
        f.write(raw)


def test(args, browser, tmp):
    fvr = args.fvr
    server, url = serve(fvr, "brainsmall")
    print(f"web-test: fvr view brainsmall serves {url}", flush=True)
    browser.open_page(url)
    state = first_view(browser, "brainsmall")
    plan = state["plan"]
    print(f"web-test: first view with no click: {state['image']['w']}x{state['image']['h']}, "
          f"{plan['filter']} oversample {plan['grid']} {plan['precision']}, predicted "
          f"{plan['predicted_db']} dB", flush=True)
    if args.screenshot:
        time.sleep(0.5)
        png = browser.send("Page.captureScreenshot", {"format": "png"})["data"]
        with open(args.screenshot, "wb") as f:
            f.write(base64.b64decode(png))
        print(f"web-test: screenshot in {args.screenshot}", flush=True)

    # 2. The same view as `fvr render`, same planner target (50 dB).
    d, u = VIEW
    img = browser.eval(f"fvr.render({json.dumps(d)}, {json.dumps(u)})")
    raw = base64.b64decode(img["b64"])
    if img["channels"] != 1 or len(raw) != 4 * img["w"] * img["h"]:
        fail(f"page image: {img['w']}x{img['h']}x{img['channels']}, {len(raw)} bytes")
    values = struct.unpack(f"<{img['w'] * img['h']}f", raw)
    if max(values) <= 0:
        fail("the page's image is black")
    write_nrrd(f"{tmp}/web.nrrd", img["w"], img["h"], raw)
    subprocess.run([fvr, "--quiet", "render", "brainsmall", "--accuracy", "50", "--dir",
                    ",".join(map(str, d)), "--up", ",".join(map(str, u)), "--out",
                    f"{tmp}/cli.nrrd"], check=True)
    cmp = subprocess.run([fvr, "compare", f"{tmp}/cli.nrrd", f"{tmp}/web.nrrd", "--json"],
                         capture_output=True, text=True)
    print(f"web-test: page vs fvr render, {img['w']}x{img['h']}: {cmp.stdout.strip()} "
          f"(floor {FLOOR_DB} dB; view {img['ms']:.1f} ms in the page)", flush=True)
    snr = json.loads(cmp.stdout)
    db = snr.get("snr_db", snr.get("db"))
    if cmp.returncode != 0 or db is None or not (db == "inf" or float(db) >= FLOOR_DB):
        fail(f"page and fvr render differ: {cmp.stdout} {cmp.stderr}")

    # 3. A drag with the mouse: previews while moving, full at rest.
    browser.eval("fvr.shown.length = 0, true")
    before = browser.eval("fvr.state().dir")
    box = browser.eval("(() => { const r = document.getElementById('view').getBoundingClientRect();"
                       " return [r.left, r.top, r.width, r.height]; })()")
    cx, cy = box[0] + box[2] / 2, box[1] + box[3] / 2
    mouse = lambda kind, x, y, buttons: browser.send("Input.dispatchMouseEvent", {
        "type": kind, "x": x, "y": y, "button": "left", "buttons": buttons, "clickCount": 1})
    mouse("mousePressed", cx, cy, 1)
    for i in range(1, 13):
        mouse("mouseMoved", cx + 12 * i, cy + 4 * i, 1)
        time.sleep(0.02)
    mouse("mouseReleased", cx + 144, cy + 48, 0)
    browser.wait("fvr.shown.length > 0 && fvr.shown[fvr.shown.length - 1].level === 0 && !fvr.state().busy",
                 60, "the full view after the drag")
    shown = browser.eval("fvr.shown")
    previews = [s for s in shown if s["level"] > 0]
    after = browser.eval("fvr.state().dir")
    side = state["image"]["w"]
    if not previews or any(p["w"] != side >> p["level"] or p["max"] <= 0 for p in previews):
        fail(f"no preview-level image while dragging: {shown}")
    if sum((a - b) ** 2 for a, b in zip(before, after)) < 1e-4:
        fail(f"the drag did not turn the view: {before} -> {after}")
    print(f"web-test: drag drew {len(previews)} preview images (level {previews[0]['level']}, "
          f"{previews[0]['w']}x{previews[0]['h']}), then full; view {before} -> {after}", flush=True)

    # 4. Bad files through the file picker, as a user would choose them.
    junk = f"{tmp}/notes.nii"
    with open(junk, "wb") as f:
        f.write(b"this is not a volume\n" * 40)
    subprocess.run([fvr, "--quiet", "convert", "brainsmall", "--out", f"{tmp}/head.nrrd"], check=True)
    with open(f"{tmp}/head.nrrd", "rb") as f:
        whole = f.read()
    with open(f"{tmp}/cut.nrrd", "wb") as f:
        f.write(whole[: len(whole) // 2])
    with open(f"{tmp}/huge.fvrvol", "wb") as f:
        f.write(b"FVRVOL1\n" + struct.pack("<3I3d", 1024, 1024, 1024, 1, 1, 1) + bytes(4096))
    doc = browser.send("DOM.getDocument")["root"]["nodeId"]
    picker = browser.send("DOM.querySelector", {"nodeId": doc, "selector": "#file"})["nodeId"]
    for path, want in [(junk, "notes.nii"), (f"{tmp}/cut.nrrd", "cut.nrrd"),
                       (f"{tmp}/huge.fvrvol", "too large for the browser")]:
        browser.eval("document.getElementById('message').textContent = '', true")
        browser.send("DOM.setFileInputFiles", {"files": [path], "nodeId": picker})
        msg = browser.wait("!fvr.state().busy && document.getElementById('message').textContent",
                           60, f"a message for {os.path.basename(path)}")
        if "\n" in msg or want not in msg or "ready" in msg:
            fail(f"{os.path.basename(path)}: message {msg!r}, wanted one line with {want!r}")
        print(f"web-test: {os.path.basename(path)} -> {msg}", flush=True)
    again = browser.eval(f"fvr.render({json.dumps(d)}, {json.dumps(u)})")
    if again["b64"] != img["b64"]:
        fail("after the bad files the page no longer renders the same view")

    # 5. Ctrl-C stops the server.
    server.send_signal(signal.SIGINT)
    try:
        code = server.wait(10)
    except subprocess.TimeoutExpired:
        fail("fvr view did not stop on SIGINT")
    if code != 130:
        fail(f"fvr view exited {code} on SIGINT, not 130")
    print("web-test: Ctrl-C stopped fvr view (exit 130)", flush=True)


def bench(args, browser):
    server, url = serve(args.fvr, "gaussians@128")
    browser.open_page(url)
    first_view(browser, "gaussians@128")
    rows = []
    for spec in ["gaussians@128", "gaussians@256"]:
        if spec != "gaussians@128":
            browser.eval(f"fvr.openSpec('{spec}').then(() => true)", 600)
        plan = browser.eval("fvr.state().plan")
        for level in [0, 1]:
            r = browser.eval(f"fvr.bench({level}, 60)", 600)
            rows.append((spec, level, plan, r["views_per_s"], r["ms_per_view"]))
    server.send_signal(signal.SIGINT)
    server.wait(10)
    print("| volume | level | plan (50 dB target) | image | ms/view | views/s |")
    print("|---|---|---|---|---|---|")
    for spec, level, p, vps, ms in rows:
        side = p["side"] >> level
        print(f"| {spec} | {level} | {p['filter']} x{p['grid']} {p['precision']} ({p['n']}³) | "
              f"{side}² | {ms:.2f} | {vps:.0f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fvr", default="target/release/fvr")
    ap.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium")
    ap.add_argument("--screenshot")
    ap.add_argument("--bench", action="store_true")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        browser = Browser(args.chromium, f"{tmp}/profile")
        try:
            bench(args, browser) if args.bench else test(args, browser, tmp)
        finally:
            browser.close()
    if not args.bench:
        print("web-test: 5 passed, 0 failed", flush=True)


if __name__ == "__main__":
    main()
