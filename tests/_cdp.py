"""A headless Chromium driven through the Chrome DevTools Protocol, for the app's browser tests
(``tests/test_app.py``, ``tests/test_app_diagnosis_browser.py``): serve a Dash app, open a
page, evaluate JavaScript, click with the mouse, type with the keyboard, give a file input a
file. Not a test module (no ``test_`` prefix): pytest puts this folder on ``sys.path``."""

from __future__ import annotations

import contextlib
import json
import shutil
import socket
import subprocess
import threading
import time
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Page:
    """A minimal Chrome DevTools Protocol client: evaluate JavaScript, type, click."""

    def __init__(self, ws_url):
        import websocket

        # no Origin header: Chromium 111+ refuses a DevTools connection from an origin it
        # was not started to allow (403 "Rejected an incoming WebSocket connection")
        self.ws = websocket.create_connection(ws_url, timeout=120, suppress_origin=True)
        self.n = 0

    def call(self, method, **params):
        self.n += 1
        self.ws.send(json.dumps({"id": self.n, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == self.n:
                return msg.get("result", {})

    def js(self, expr):
        res = self.call("Runtime.evaluate", expression=expr, returnByValue=True,
                        awaitPromise=True)  # fmt: skip
        return res.get("result", {}).get("value")

    def wait(self, expr, timeout=120.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            value = self.js(expr)
            if value:
                return value
            time.sleep(0.3)
        raise AssertionError(
            f"timed out waiting for {expr}: {self.js('document.body.innerText')[:800]}"
        )

    def click(self, element_js):
        """A real mouse click (pointer events) at the centre of an element."""
        x, y = self.js(f"(() => {{ const e = {element_js}; e.scrollIntoView({{block: 'center'}});"
                       " const b = e.getBoundingClientRect();"
                       " return [b.x + b.width / 2, b.y + b.height / 2]; })()")  # fmt: skip
        for kind in ("mouseMoved", "mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left",
                      clickCount=1)  # fmt: skip

    def type_at(self, element_js, text, enter=False):
        """Select the text of the input ``element_js`` and type ``text`` (real key events);
        returns the input's value after."""
        self.js(f"(() => {{ const el = {element_js}; el.scrollIntoView(); el.focus();"
                " el.select(); })()")  # fmt: skip
        self.call("Input.insertText", text=text)
        if enter:
            for kind, text in (("keyDown", "\r"), ("keyUp", "")):  # keyDown + text: keypress
                self.call("Input.dispatchKeyEvent", type=kind, key="Enter", code="Enter",
                          text=text, windowsVirtualKeyCode=13, nativeVirtualKeyCode=13)  # fmt: skip
        return self.js(f"{element_js}.value")

    def type_into(self, field_key, text, enter=False):
        """Type ``text`` into the app's parameter field ``field_key``."""
        el = f'document.getElementById(\'{{"key":"{field_key}","type":"field"}}\')'
        return self.type_at(el, text, enter)

    def set_file(self, selector, path):
        """Give the file input under ``selector`` the file ``path``, as choosing it in the
        file dialog does (the input's change event follows)."""
        root = self.call("DOM.getDocument", depth=-1)["root"]["nodeId"]
        node = self.call("DOM.querySelector", nodeId=root, selector=selector)["nodeId"]
        assert node, f"no element {selector!r} on the page"
        self.call("DOM.setFileInputFiles", files=[str(path)], nodeId=node)


def chromium() -> str:
    """The Chromium executable; the test skips when there is none (CI installs it in
    .ci/run). Call it first, before a test's expensive setup."""
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("chromium is not installed (CI installs it in .ci/run)")
    return exe


@contextlib.contextmanager
def served_page(app, tmp_path: Path) -> Iterator[tuple[Page, int, Path]]:
    """``(page, port, downloads)``: the Dash ``app`` served on a free port and a blank page of
    a headless Chromium (downloads allowed into ``downloads``). Skips when Chromium is not
    installed (CI installs it in .ci/run)."""
    exe = chromium()
    from werkzeug.serving import make_server

    port = free_port()
    server = make_server("127.0.0.1", port, app.server, threaded=True)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    profile, downloads = tmp_path / "profile", tmp_path / "downloads"
    (profile / "DevToolsActivePort").unlink(missing_ok=True)  # a former browser's port
    proc = subprocess.Popen(
        [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         f"--user-data-dir={profile}", "--remote-debugging-port=0", "--window-size=1400,1000",
         "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        for _ in range(300):
            f = profile / "DevToolsActivePort"
            if f.exists() and f.read_text().strip():
                break
            time.sleep(0.1)
        cdp_port = int((profile / "DevToolsActivePort").read_text().split()[0])
        targets = json.load(urllib.request.urlopen(f"http://127.0.0.1:{cdp_port}/json/list"))
        page = Page(next(t for t in targets if t["type"] == "page")["webSocketDebuggerUrl"])
        page.call("Browser.setDownloadBehavior", behavior="allow",
                  downloadPath=str(downloads))  # fmt: skip
        yield page, port, downloads
    finally:
        proc.terminate()
        proc.wait(timeout=30)
        server.shutdown()
