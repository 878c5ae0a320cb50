#!/usr/bin/python3
"""page_driver.py — drives murk's comparison page (report.html) in Debian's headless Chromium the way a
person uses it (keys, clicks, the mouse over the image) and prints what the page then shows, for
tests/test_report_page.c and for the screenshot in docs/. Python's standard library only: it talks the
DevTools protocol over the pipe Chromium opens with --remote-debugging-pipe (fds 3 and 4, messages ended
by a NUL), so it needs no network port, no websocket library and no npm package.

    /usr/bin/python3 tests/page_driver.py [--chromium PATH] [--size WxH] SCRIPT

SCRIPT has one command a line (blank lines and lines starting with # are skipped):
    open FILE            load FILE and wait until the page is ready (window.murkPage.ready)
    key K                press and release the key K (one character)
    click CSS            a left click at the middle of the element
    click_at CSS FX      a left click at the fraction FX of the element's width, at its vertical middle
    hover X Y            the mouse to the middle of the page image's pixel (X, Y)
    wheel X Y DY         a mouse wheel step of DY over the page image's pixel (X, Y)
    pixel X Y            prints "pixel X Y R G B A": the view canvas's pixel at image pixel (X, Y)
    eval JS              prints "eval JSON": the expression's value
    text CSS             prints "text JSON": the element's textContent
    screenshot PNG [H]   the window as PNG (H: the page's full height up to H pixels)
At the end it prints "requests N" (loads other than the page itself and data: URIs, each on a
"request URL" line), then "errors N" (exceptions and console errors, each on an "error TEXT" line).
Exit status 0, or 1 after a message on stderr when Chromium or a command fails.
"""
import base64
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--force-device-scale-factor=1", "--remote-debugging-pipe"]


class Browser:
    def __init__(self, chromium, width, height):
        self.profile = tempfile.mkdtemp(prefix="murk-page-")
        to_r, self.to_w = os.pipe()
        self.from_r, from_w = os.pipe()

        def child():  # Chromium reads commands on fd 3 and answers on fd 4
            a, b = os.dup(to_r), os.dup(from_w)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.proc = subprocess.Popen(
            [chromium] + FLAGS + ["--user-data-dir=" + self.profile, "--window-size=%d,%d" % (width, height),
                                  "about:blank"],
            close_fds=False, preexec_fn=child, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL)
        os.close(to_r)
        os.close(from_w)
        self.buf = b""
        self.next_id = 0
        self.events = []
        self.session = None
        targets = self.call("Target.getTargets")["targetInfos"]
        page = next(t for t in targets if t["type"] == "page")
        self.session = self.call("Target.attachToTarget", targetId=page["targetId"], flatten=True)["sessionId"]
        for domain in ("Page", "Runtime", "Log", "Network"):
            self.call(domain + ".enable")
        self.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)

    def call(self, method, timeout=30, **params):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params}
        if self.session and not method.startswith("Target."):
            msg["sessionId"] = self.session
        os.write(self.to_w, json.dumps(msg).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            while b"\0" in self.buf:
                raw, self.buf = self.buf.split(b"\0", 1)
                m = json.loads(raw)
                if m.get("id") == self.next_id:
                    if "error" in m:
                        raise RuntimeError("%s: %s" % (method, m["error"].get("message")))
                    return m.get("result", {})
                if "method" in m:
                    self.events.append(m)
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self.from_r], [], [], left)[0]:
                raise RuntimeError("%s: no answer from Chromium in %d s" % (method, timeout))
            chunk = os.read(self.from_r, 1 << 20)
            if not chunk:
                raise RuntimeError("%s: Chromium closed the pipe" % method)
            self.buf += chunk

    def eval(self, expr):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            d = r["exceptionDetails"]
            raise RuntimeError("eval %s: %s" % (expr, d.get("exception", {}).get("description", d.get("text"))))
        return r["result"].get("value")

    def close(self):
        self.proc.terminate()  # Chromium shuts down on SIGTERM (a second faster than Browser.close)
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self.to_w)
        os.close(self.from_r)
        shutil.rmtree(self.profile, ignore_errors=True)


def element_point(b, css, fx=0.5):
    r = b.eval("(() => { const r = document.querySelector(%s).getBoundingClientRect(); return [r.left, r.top, "
               "r.width, r.height]; })()" % json.dumps(css))
    return r[0] + fx * r[2], r[1] + r[3] / 2


def pixel_point(b, x, y):
    return b.eval("murkPage.canvasToClient(...murkPage.imageToCanvas(%d, %d))" % (x, y))


def click(b, x, y):
    for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
        b.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)


def run(b, cmd, arg, page_url):
    if cmd == "open":
        url = "file://" + os.path.abspath(arg)
        page_url.append(url)
        b.call("Page.navigate", url=url)
        deadline = time.monotonic() + 30
        while not b.eval("!!(window.murkPage && window.murkPage.ready)"):
            if time.monotonic() > deadline:
                raise RuntimeError("open %s: the page did not get ready in 30 s" % arg)
            time.sleep(0.05)
    elif cmd == "key":
        for kind in ("keyDown", "keyUp"):
            b.call("Input.dispatchKeyEvent", type=kind, key=arg, text=arg if kind == "keyDown" else "")
    elif cmd == "click":
        click(b, *element_point(b, arg))
    elif cmd == "click_at":
        css, fx = arg.rsplit(" ", 1)
        click(b, *element_point(b, css, float(fx)))
    elif cmd == "hover":
        x, y = pixel_point(b, *map(int, arg.split()))
        b.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
    elif cmd == "wheel":
        px, py, dy = arg.split()
        x, y = pixel_point(b, int(px), int(py))
        b.call("Input.dispatchMouseEvent", type="mouseWheel", x=x, y=y, deltaX=0, deltaY=float(dy))
    elif cmd == "pixel":
        x, y = map(int, arg.split())
        v = b.eval("(() => { const [cx, cy] = murkPage.imageToCanvas(%d, %d); return Array.from(document"
                   ".getElementById('view').getContext('2d').getImageData(Math.floor(cx), Math.floor(cy), 1, 1)"
                   ".data); })()" % (x, y))
        print("pixel %d %d %d %d %d %d" % (x, y, *v))
    elif cmd == "eval":
        print("eval " + json.dumps(b.eval(arg)))
    elif cmd == "text":
        print("text " + json.dumps(b.eval("document.querySelector(%s).textContent" % json.dumps(arg))))
    elif cmd == "screenshot":
        parts = arg.split()
        params = {"format": "png"}
        if len(parts) > 1:
            h = min(int(parts[1]), int(b.eval("document.documentElement.scrollHeight")))
            w = int(b.eval("document.documentElement.clientWidth"))
            params.update(captureBeyondViewport=True, clip={"x": 0, "y": 0, "width": w, "height": h, "scale": 1})
        data = base64.b64decode(b.call("Page.captureScreenshot", **params)["data"])
        with open(parts[0], "wb") as f:
            f.write(data)
    else:
        raise RuntimeError("unknown command '%s'" % cmd)


def report(b, page_url):
    requests, errors = [], []
    for e in b.events:
        p = e.get("params", {})
        if e["method"] == "Network.requestWillBeSent":
            url = p["request"]["url"]
            if not url.startswith("data:") and url not in page_url:
                requests.append(url)
        elif e["method"] == "Runtime.exceptionThrown":
            d = p["exceptionDetails"]
            errors.append(d.get("exception", {}).get("description", d.get("text", "")))
        elif e["method"] == "Runtime.consoleAPICalled" and p.get("type") == "error":
            errors.append(" ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", [])))
        elif e["method"] == "Log.entryAdded" and p["entry"]["level"] == "error":
            errors.append(p["entry"]["text"])
    print("requests %d" % len(requests))
    for u in requests:
        print("request " + u)
    print("errors %d" % len(errors))
    for t in errors:
        print("error " + t.replace("\n", " | "))


def main():
    args = sys.argv[1:]
    chromium = shutil.which("chromium") or "/usr/lib/chromium/chromium"
    width, height = 1200, 900
    while args and args[0].startswith("--"):
        if args[0] == "--chromium":
            chromium = args[1]
        elif args[0] == "--size":
            width, height = map(int, args[1].split("x"))
        else:
            sys.exit("page_driver.py: unknown option " + args[0])
        args = args[2:]
    if len(args) != 1:
        sys.exit(__doc__)
    with open(args[0]) as f:
        script = [ln.strip() for ln in f if ln.strip() and not ln.lstrip().startswith("#")]
    b = None
    try:
        b = Browser(chromium, width, height)
        page_url = []
        for line in script:
            cmd, _, arg = line.partition(" ")
            run(b, cmd, arg, page_url)
            sys.stdout.flush()
        report(b, page_url)
    except (RuntimeError, OSError, StopIteration, ValueError) as e:
        sys.stdout.flush()
        print("page_driver.py: %s" % e, file=sys.stderr)
        return 1
    finally:
        if b:
            b.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
