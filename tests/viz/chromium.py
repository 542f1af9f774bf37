"""A headless Chromium driven over the DevTools protocol (CDP), for the animation tests.

Chromium's one-shot ``--screenshot`` takes its picture at an arbitrary point of the page's
asynchronous loading, so the tests drive the browser instead: load the file, wait until the
viewer has built its scene, then screenshot, read the DOM and list every request the page made.

The page's requests are told from the browser's own by who makes them: CDP's
``Network.requestWillBeSent`` events of the page's target and of every target the page starts
(its workers and out-of-process frames, attached automatically and paused until their Network
domain is on: ``Target.setAutoAttach`` with ``waitForDebuggerOnStart``). Chromium's own services
(component and update checks, which ``--disable-background-networking`` does not silence
entirely) run in the browser process, in no target of the page, so they are never counted. The
browser runs offline with a fresh profile: its only way out is a proxy run here that records the
request line of every connection (from any of the browser's processes) and then closes it; the
tests use it to show that a request the page makes does leave the browser, and that the CDP
record sees it.
"""

from __future__ import annotations

import base64
import json
import os
import re
import shutil
import socket
import subprocess
import tempfile
import threading
import time
import urllib.request

CHROMIUM_FLAGS = [
    "--headless=new",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-default-apps",
    "--disable-extensions",
    "--disable-domain-reliability",
    "--disable-client-side-phishing-detection",
    "--no-default-browser-check",
    "--no-first-run",
    "--proxy-bypass-list=<-loopback>",
    "--hide-scrollbars",
]


# attach to every target the page starts, paused until its Network domain is enabled
AUTO_ATTACH = {"autoAttach": True, "waitForDebuggerOnStart": True, "flatten": True}


def chromium_path() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    return None


class DeadProxy:
    """An HTTP proxy on a free loopback port that answers nothing: it records the first line of
    each connection (``CONNECT host:443 ...`` or ``GET http://...``) and closes it."""

    def __init__(self):
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.lines: list[str] = []
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self):
        while True:
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            threading.Thread(target=self._record, args=(conn,), daemon=True).start()

    def _record(self, conn):
        with conn:
            conn.settimeout(5)
            try:
                head = conn.recv(4096)
            except OSError:
                head = b""
            # a connection closed before any request (Chromium preconnects to its proxy)
            # asked for nothing
            if head:
                self.lines.append(head.split(b"\r\n", 1)[0].decode("latin-1"))

    def hosts(self) -> list[str]:
        """The host of each recorded request."""
        out = []
        for line in self.lines:
            parts = line.split()
            target = parts[1] if len(parts) > 1 else line
            out.append(re.sub(r"^[a-z]+://", "", target).split("/")[0].rsplit(":", 1)[0])
        return out

    def close(self):
        self.server.close()


class Browser:
    """``with Browser(800, 600) as b: b.open(path); png = b.screenshot()``."""

    def __init__(self, width: int = 800, height: int = 600):
        self.width, self.height = width, height
        self.profile = tempfile.mkdtemp(prefix="armdyn-chromium-")
        self.proxy = DeadProxy()
        self.proc = subprocess.Popen(
            [
                chromium_path(),
                *CHROMIUM_FLAGS,
                f"--proxy-server=127.0.0.1:{self.proxy.port}",
                f"--window-size={width},{height}",
                f"--user-data-dir={self.profile}",
                "--remote-debugging-port=0",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        port = None
        deadline = time.monotonic() + 60
        while port is None and time.monotonic() < deadline:
            line = self.proc.stderr.readline()
            if not line and self.proc.poll() is not None:
                break
            m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
            if m:
                port = int(m.group(1))
        if port is None:
            self.close()
            raise RuntimeError("chromium did not start its DevTools endpoint")
        # stderr is not read any more: let it drain so the browser never blocks on it
        threading.Thread(target=self.proc.stderr.read, daemon=True).start()
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=30) as r:
            page = next(t for t in json.load(r) if t["type"] == "page")
        from websockets.sync.client import connect

        # a connection held across calls (not a `with` block): the page is driven step by step
        self.ws = connect(page["webSocketDebuggerUrl"], max_size=None, open_timeout=30)
        self.ws.__enter__()
        self._id = 0
        self.events: list[dict] = []
        self.sessions: list[dict] = []  # the targets the page started (Target.attachedToTarget)
        self.call("Network.enable")
        self.call("Page.enable")
        self.call("Runtime.enable")
        self.call("Target.setAutoAttach", **AUTO_ATTACH)

    def _send(self, method: str, session: str | None = None, **params) -> int:
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params}
        if session is not None:
            msg["sessionId"] = session
        self.ws.send(json.dumps(msg))
        return self._id

    def _event(self, msg: dict) -> None:
        """Record an event; a target the page started (a worker, a frame) gets its Network
        domain and the same auto-attach before it runs (it waits for the debugger)."""
        self.events.append(msg)
        if msg.get("method") == "Target.attachedToTarget":
            session = msg["params"]["sessionId"]
            self.sessions.append(msg["params"]["targetInfo"])
            self._send("Network.enable", session)
            self._send("Target.setAutoAttach", session, **AUTO_ATTACH)
            self._send("Runtime.runIfWaitingForDebugger", session)

    def call(self, method: str, timeout: float = 120.0, **params):
        """Send a command to the page's target and return its result (events that arrive
        meanwhile are recorded)."""
        own = self._send(method, **params)
        deadline = time.monotonic() + timeout
        while True:
            msg = json.loads(self.ws.recv(timeout=max(0.1, deadline - time.monotonic())))
            if msg.get("id") == own and "sessionId" not in msg:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg["result"]
            if "method" in msg:
                self._event(msg)

    def evaluate(self, expression: str, timeout: float = 120.0):
        """The value of a JavaScript expression (a promise is awaited)."""
        res = self.call(
            "Runtime.evaluate",
            timeout=timeout,
            expression=expression,
            awaitPromise=True,
            returnByValue=True,
        )
        if "exceptionDetails" in res:
            raise RuntimeError(f"JavaScript error: {res['exceptionDetails']}")
        return res["result"].get("value")

    def open(self, path: str | os.PathLike) -> None:
        url = "file://" + os.path.abspath(path)
        self.call("Page.navigate", url=url)
        deadline = time.monotonic() + 120
        while self.evaluate("document.readyState") != "complete":
            if time.monotonic() > deadline:
                raise RuntimeError(f"{url} did not finish loading")
            time.sleep(0.1)

    def requested_urls(self) -> list[str]:
        """Every URL the page asked the network stack for: its own requests (the document
        itself first) and those of the workers and frames it started, in order; never the
        browser's own."""
        return [
            e["params"]["request"]["url"]
            for e in self.events
            if e.get("method") == "Network.requestWillBeSent"
        ]

    def console_errors(self) -> list[str]:
        out = []
        for e in self.events:
            if e.get("method") == "Runtime.exceptionThrown":
                out.append(json.dumps(e["params"]["exceptionDetails"])[:500])
            elif e.get("method") == "Runtime.consoleAPICalled" and e["params"]["type"] == "error":
                out.append(json.dumps(e["params"]["args"])[:500])
        return out

    def screenshot(self) -> bytes:
        res = self.call("Page.captureScreenshot", format="png")
        return base64.b64decode(res["data"])

    def close(self) -> None:
        ws = getattr(self, "ws", None)
        if ws is not None:
            ws.close()
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        shutil.rmtree(self.profile, ignore_errors=True)
        self.proxy.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
