#!/usr/bin/env python3
"""The web page in a real browser: serves target/web/ on 127.0.0.1, opens it in headless Chromium
with WebGPU enabled (SwiftShader is the adapter) in test mode, takes the frame the page read back
from the GPU (a PNG data URL in #hadou-test-result) and compares it with `hadou render` of the same
scene, time and size: the mean absolute 8-bit difference over the RGB channels must be at most 1.
Each case runs on WebGPU and with backend=webgl (the WebGL2 fallback, where the CPU backend draws).
Also checks that a bad URL is a message, not a blank page.

usage: web_test.py HADOU_BINARY [--chromium PATH] [--json OUT]
"""

import argparse
import base64
import functools
import http.server
import json
import os
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WEB = os.path.join(ROOT, "target", "web")
WIDTH, HEIGHT = 320, 180
# (scene, time): the Kamehameha at 1.5 s, one light-, one shadow- and two soft- scenes (the two
# maps' exact resolve, and the traced resolve of a disc lamp), and the glare (drawn on the GPU in
# the page too).
CASES = [
    ("kamehameha", 1.5),
    ("light-from-front", 1.0),
    ("shadow-wave-top", 1.0),
    ("soft-gradient", 0.5),
    ("soft-disc", 0.5),
    ("glare-kamehameha", 1.5),
]
MAX_MEAN_DIFF = 1.0
# How long one page may take to show its frame (SwiftShader compiles the wave shader on the CPU).
PAGE_TIMEOUT_S = 300


def png_rgb(data):
    """Decodes an 8-bit, non-interlaced RGB or RGBA PNG into (width, height, rows of RGB bytes)."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, head = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
    w, h, depth, colour, _, _, interlace = head
    if depth != 8 or colour not in (2, 6) or interlace:
        raise ValueError(f"unsupported PNG (depth {depth}, colour type {colour}, interlace {interlace})")
    bpp = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(v for i, v in enumerate(line) if i % bpp < 3))
        prev = line
    return w, h, rows


def mean_diff(a, b):
    (wa, ha, ra), (wb, hb, rb) = a, b
    if (wa, ha) != (wb, hb):
        raise ValueError(f"sizes differ: {wa}x{ha} against {wb}x{hb}")
    total = sum(abs(x - y) for r1, r2 in zip(ra, rb) for x, y in zip(r1, r2))
    return total / (wa * ha * 3)


def serve():
    handler = functools.partial(QuietHandler, directory=WEB)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


class QuietHandler(http.server.SimpleHTTPRequestHandler):
    extensions_map = {**http.server.SimpleHTTPRequestHandler.extensions_map, ".wasm": "application/wasm",
                      ".js": "text/javascript"}

    def log_message(self, *args):
        pass


class Browser:
    """Headless Chromium driven over the DevTools protocol on a pipe (--remote-debugging-pipe:
    JSON messages ending in a NUL byte, commands on fd 3, replies on fd 4); no package needed."""

    def __init__(self, chromium):
        self.profile = tempfile.mkdtemp(prefix="hadou-chromium-")
        to_chrome_r, self.to_chrome = os.pipe()
        self.from_chrome, from_chrome_w = os.pipe()
        cmd = [chromium] + ([] if os.environ.get("HADOU_WEB_HEADFUL") else ["--headless"]) + ["--no-sandbox", "--no-first-run", "--remote-debugging-pipe",
               f"--user-data-dir={self.profile}", "--enable-unsafe-webgpu", "--enable-features=Vulkan",
               "--use-angle=swiftshader", "--use-webgpu-adapter=swiftshader", "--enable-unsafe-swiftshader",
               "--disable-gpu-watchdog", "--window-size=1280,800",
               "about:blank"]

        def child_fds():
            os.dup2(to_chrome_r, 3)
            os.dup2(from_chrome_w, 4)

        self.log = open(os.path.join(self.profile, "chromium.log"), "w")
        self.proc = subprocess.Popen(cmd, preexec_fn=child_fds, stdout=self.log, stderr=self.log, close_fds=False)
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self.next_id, self.buffer, self.console = 0, b"", []

    def send(self, method, params=None, session=None):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.to_chrome, json.dumps(msg).encode() + b"\0")
        want = self.next_id
        while True:
            while b"\0" not in self.buffer:
                chunk = os.read(self.from_chrome, 1 << 20)
                if not chunk:
                    raise RuntimeError("Chromium closed the DevTools pipe")
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("method") in ("Runtime.consoleAPICalled", "Runtime.exceptionThrown", "Log.entryAdded"):
                self.console.append(json.dumps(reply.get("params"))[:600])
            if reply.get("id") == want:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})

    def page_texts(self, url, ids, timeout_s):
        """Opens `url` in a new tab and waits until one of the elements `ids` has text (or the
        timeout); returns every element's text, by id, and the seconds it took."""
        target = self.send("Target.createTarget", {"url": url})["targetId"]
        session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        self.console = []
        self.send("Runtime.enable", {}, session)
        self.send("Log.enable", {}, session)
        expr = "JSON.stringify(Object.fromEntries(%s.map(i => [i, (document.getElementById(i) || {}).textContent || ''])))" \
            % json.dumps(ids + ["hadou-test-timing", "hadou-status", "hadou-message"])
        started, texts = time.time(), {}
        while time.time() - started < timeout_s:
            r = self.send("Runtime.evaluate", {"expression": expr, "returnByValue": True}, session)
            texts = json.loads(r.get("result", {}).get("value") or "{}")
            if any(texts.get(i) for i in ids):
                break
            time.sleep(0.25)
        self.send("Target.closeTarget", {"targetId": target})
        return texts, time.time() - started

    def close(self):
        self.proc.kill()
        self.proc.wait()
        self.log.close()


def viewer_checks(browser, base):
    """Drives the interactive page (backend=webgl) through window.hadou; yields (check, ok, detail)."""
    target = browser.send("Target.createTarget", {"url": f"{base}?backend=webgl&scene=kamehameha"})["targetId"]
    session = browser.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]

    def js(expr):
        r = browser.send("Runtime.evaluate", {"expression": expr, "returnByValue": True, "awaitPromise": True}, session)
        return r.get("result", {}).get("value")

    def wait(expr, seconds=120):
        started = time.time()
        while time.time() - started < seconds:
            v = js(expr)
            if v:
                return v
            time.sleep(0.25)
        return None

    status = wait("window.hadou && document.getElementById('hadou-status').textContent")
    yield "starts", bool(status) and "WebGL2" in status, status or "no status line"
    js("""(() => { const h = window.hadou; h.drop_begin();
        h.drop_file('bad.toml', new TextEncoder().encode('[camera]\\nfov = \"wide\"\\n')); h.drop_end(); })()""")
    message = wait("document.getElementById('hadou-message').textContent", 60) or ""
    yield "a dropped scene with a TOML error", message.startswith("/dropped/bad.toml:2:") and "last good scene" in message, message
    refusal = js("window.hadou.refuse_file('huge.toml', 2e9)") or ""
    yield "a file over its size limit", "not read" in refusal and "huge.toml" in refusal, refusal
    fine = js("window.hadou.refuse_file('hero.glb', 1e6)")
    yield "a file within its limit", fine is None, repr(fine)
    browser.send("Target.closeTarget", {"targetId": target})


def reference(hadou, scene, t, out):
    subprocess.run([hadou, "render", os.path.join(ROOT, "scenes", scene + ".toml"), "--time", str(t),
                    "--width", str(WIDTH), "--height", str(HEIGHT), "--backend", "cpu", "-o", out], check=True)
    with open(out, "rb") as f:
        return png_rgb(f.read())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("hadou")
    ap.add_argument("--chromium", default="chromium")
    ap.add_argument("--json")
    a = ap.parse_args()
    if not os.path.exists(os.path.join(WEB, "index.html")):
        sys.exit("error: target/web/index.html is missing: run web/build first")
    server = serve()
    base = f"http://127.0.0.1:{server.server_address[1]}/index.html"
    scratch = tempfile.mkdtemp(prefix="hadou-web-test-")
    failures, results = [], []
    browser = Browser(a.chromium)
    for scene, t in CASES:
        ref = reference(a.hadou, scene, t, os.path.join(scratch, scene + ".png"))
        for api in ("webgpu", "webgl"):
            url = f"{base}?scene={scene}&time={t}&width={WIDTH}&height={HEIGHT}&test=1"
            if api == "webgl":
                url += "&backend=webgl"
            texts, secs = browser.page_texts(url, ["hadou-test-result", "hadou-test-error"], PAGE_TIMEOUT_S)
            result, error = texts.get("hadou-test-result", ""), texts.get("hadou-test-error", "")
            label = f"{scene} t={t} {api}"
            if error or not result.startswith("data:image/png;base64,"):
                status = texts.get("hadou-status")
                failures.append(f"{label}: no frame ({error or 'no result'}; status: {status})")
                print(f"FAIL {label}: {error or 'no result after %d s' % secs} (status: {status}); the page's console:\n  "
                      + "\n  ".join(browser.console[-12:]))
                continue
            timing = texts.get("hadou-test-timing", "")
            got = png_rgb(base64.b64decode(result.split(",", 1)[1]))
            d = mean_diff(got, ref)
            timing = json.loads(timing) if timing else {}
            results.append({"scene": scene, "time": t, "api": api, "mean_abs_diff": round(d, 4),
                            "page_backend": timing.get("backend"), "adapter": timing.get("adapter"),
                            "first_frame_ms": timing.get("first_frame_ms"), "frame_ms": timing.get("frame_ms"),
                            "page_load_s": round(secs, 1)})
            ok = d <= MAX_MEAN_DIFF
            print(f"{'ok  ' if ok else 'FAIL'} {label}: mean |page - hadou render| = {d:.4f} (≤ {MAX_MEAN_DIFF}); "
                  f"drawn by the {timing.get('backend')} backend on {timing.get('adapter')!r}, "
                  f"first frame {timing.get('first_frame_ms')} ms, then {timing.get('frame_ms')} ms a frame; page run {secs:.1f} s")
            if not ok:
                failures.append(f"{label}: mean difference {d:.4f} > {MAX_MEAN_DIFF}")
    # The viewer itself (WebGL2, which headless Chromium can present): it starts, and a dropped
    # scene with a TOML error is the loader's file:line:col message while the last good scene
    # stays; a file over its size limit is refused before it is read.
    for check, ok, detail in viewer_checks(browser, base):
        print(f"{'ok  ' if ok else 'FAIL'} viewer: {check}: {detail}")
        if not ok:
            failures.append(f"viewer: {check}: {detail}")
    # A bad URL is a message in the page, not a blank page.
    for query, want in [("scene=no-such-scene&test=1", "no preset scene"), ("time=soon&test=1", "time=`soon`")]:
        texts, _ = browser.page_texts(f"{base}?{query}", ["hadou-test-error", "hadou-test-result"], 120)
        error = texts.get("hadou-test-error", "")
        ok = want in error
        print(f"{'ok  ' if ok else 'FAIL'} ?{query}: {error or 'no message'}")
        if not ok:
            failures.append(f"?{query}: expected a message containing {want!r}, got {error!r}")
    browser.close()
    server.shutdown()
    if a.json:
        with open(a.json, "w") as f:
            json.dump(results, f, indent=2)
    if failures:
        print("\n".join(["web page test failed:"] + failures), file=sys.stderr)
        sys.exit(1)
    print(f"web page test: {len(results)} frames within {MAX_MEAN_DIFF} of hadou render")


if __name__ == "__main__":
    main()
