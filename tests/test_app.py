"""recipdyn app: the callbacks as functions, and the page in a real headless Chromium
(load it, change a parameter and see the plots update, click a fault-map cell and see that
point simulated), driven through the Chrome DevTools Protocol."""

import json
import shutil
import socket
import subprocess
import threading
import time
import urllib.request

import numpy as np
import pytest

from recipdyn.app import WIDGETS, build_app, point_from_click, run_figures, sweep_figure
from recipdyn.errors import ParameterError
from recipdyn.model.parameters import CompressorParams
from recipdyn.sweep.run import run_sweep
from recipdyn.sweep.spec import SweepSpec, parse_axis


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    out = tmp_path_factory.mktemp("appsweep")
    spec = SweepSpec(axes=(parse_axis("rc=0.2mm:2mm:3:log"), parse_axis("d=0:2mm:2")),
                     measures=("peak",), settings=dict(revolutions=0.5, transient=0))  # fmt: skip
    run_sweep(spec, out, backend="serial", progress=False)
    return out


def test_every_numeric_parameter_has_a_widget_with_its_range():
    names = {p.name for p in WIDGETS}
    assert {"rc", "d", "omega", "m2", "m3", "J2", "theta_c_offset"} <= names
    assert all(p.unit is not None and p.low <= p.default <= p.high for p in WIDGETS)


def test_run_figures_are_the_simulation():
    figs, status = run_figures(dict(rc=1e-3, d=1e-3, omega=20.0), 2.0, 2000.0)
    sig, spec, _, sec, _ = figs
    a = np.asarray(sig.data[0].y)
    assert np.abs(a).max() == pytest.approx(57.66, rel=0.01)  # the base case's peak
    T = 2 * np.pi / 20.0
    t_end = np.asarray(sig.data[0].x)[-1]  # the last sample, just before 2T
    assert len(sec.data[0].x) == int(np.floor(t_end / T + 1e-9)) + 1 == 2
    assert spec.layout.yaxis.type == "log"
    assert "rc = 1 mm" in status
    with pytest.raises(ParameterError, match="rc"):
        run_figures(dict(rc=-1.0), 1.0, 2000.0)
    with pytest.raises(ParameterError, match="revolutions"):
        run_figures({}, 0.0, 2000.0)


def test_sweep_figure_and_click(store):
    fig, options, shown = sweep_figure(store)
    assert shown == "peak_a" and "peak_a" in options
    assert fig.layout.yaxis.type == "log"  # rc was swept on a log grid
    values = point_from_click(store, {"points": [{"x": 2.1e-3, "y": 0.62e-3}]})
    assert values["d"] == pytest.approx(2e-3)
    assert values["rc"] == pytest.approx(np.sqrt(0.2e-3 * 2e-3), rel=1e-12)  # the log grid's middle
    assert CompressorParams(**values).rc == values["rc"]
    with pytest.raises(ParameterError, match="not found"):
        sweep_figure(store / "nope")


# --- a real browser -----------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class _Page:
    """A minimal Chrome DevTools Protocol client: evaluate JavaScript in one page."""

    def __init__(self, ws_url):
        import websocket

        self.ws = websocket.create_connection(ws_url, timeout=60)
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

    def wait(self, expr, timeout=90.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            value = self.js(expr)
            if value:
                return value
            time.sleep(0.3)
        raise AssertionError(
            f"timed out waiting for {expr}: {self.js('document.body.innerText')[:500]}"
        )


@pytest.mark.browser
def test_app_in_headless_chromium(store, tmp_path):
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("chromium is not installed (CI installs it in .ci/run)")
    from werkzeug.serving import make_server

    port = _free_port()
    server = make_server("127.0.0.1", port, build_app(store).server, threaded=True)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    profile = tmp_path / "profile"
    proc = subprocess.Popen(
        [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         f"--user-data-dir={profile}", "--remote-debugging-port=0", "about:blank"],
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
        page = _Page(next(t for t in targets if t["type"] == "page")["webSocketDebuggerUrl"])
        page.call("Page.navigate", url=f"http://127.0.0.1:{port}/")
        # the page loads and the first simulation (the base case) is drawn
        first = page.wait("(document.getElementById('status')||{}).innerText")
        assert "omega = 20 rad/s" in first
        n_points = page.wait(
            "(() => { const g = document.querySelector('#g-signal "
            ".js-plotly-plot'); return g && g._fullData && g._fullData.length"
            " && g._fullData[0].y.length; })()"
        )  # decoded by plotly.js
        assert n_points > 1000
        # change a parameter by typing into its field (real key events) and pressing Enter
        page.js(
            "(() => { const el = document.getElementById('p-omega'); el.focus(); el.select(); })()"
        )
        page.call("Input.insertText", text="40")
        for kind in ("keyDown", "keyUp"):
            page.call("Input.dispatchKeyEvent", type=kind, key="Enter", code="Enter",
                      windowsVirtualKeyCode=13, nativeVirtualKeyCode=13)  # fmt: skip
        assert page.js("document.getElementById('p-omega').value") == "40"
        page.js("document.getElementById('run').click()")
        status = page.wait(
            "(() => { const s = document.getElementById('status').innerText;"
            " return s.includes('omega = 40') && s; })()"
        )
        assert "omega = 40 rad/s" in status
        # the fault map is drawn; click its (rc = 2 mm, d = 2 mm) cell
        page.wait(
            "(() => { const g = document.querySelector('#sweep .js-plotly-plot');"
            " return g && g._fullData && g._fullData.length"
            " && g._fullData[0].type === 'heatmap'; })()"
        )
        page.js("""(() => { const g = document.querySelector('#sweep .js-plotly-plot');
            g.emit('plotly_click', {points: [{x: 0.002, y: 0.002, curveNumber: 0,
                                              pointNumber: [2, 1]}]}); })()""")
        status = page.wait(
            "(() => { const s = document.getElementById('status').innerText;"
            " return s.includes('rc = 2 mm') && s; })()"
        )
        assert "d = 2 mm" in status
        assert page.js("document.getElementById('p-rc').value") in (
            "0.002",
            "0.0020000000000000005",
        )
    finally:
        proc.terminate()
        proc.wait(timeout=30)
        server.shutdown()
