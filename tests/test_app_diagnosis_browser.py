"""The app's diagnosis page in a real headless Chromium (the Chrome DevTools Protocol, as
``tests/test_app.py``). The page has a tab of its own and an address (``#diagnose``); a
NetCDF record with the four sensor channels, chosen in the file dialog, is diagnosed on it:
the class probabilities in a table (summing to 1 to their rounding, the named class the most
probable), the severity with its interval, the evidence one row an item (what was measured,
its value, what it means), the channels used, and the overlay image decoded by the browser
and drawn across at least 80 % of the page's width; no path of the server anywhere in the
page. The same record given a crank speed outside the shipped diagnoser's domain is withheld,
in a red box with the reason and no probabilities; a file of a type the page cannot read is
told with the types it can."""

import tempfile

import pytest

from _cdp import chromium, served_page
from recipdyn.app import build_app
from recipdyn.app.diagnosis import example_record


def _el(id_: str) -> str:
    return f"document.getElementById('{id_}')"


def _shown(id_: str) -> str:
    return f"(!!{_el(id_)} && getComputedStyle({_el(id_)}).display !== 'none')"


def _rows(id_: str) -> str:
    """The cells' texts of a table's body rows."""
    return (f"[...document.querySelectorAll('#{id_} tbody tr')]"
            ".map(r => [...r.cells].map(c => c.innerText.trim()))")  # fmt: skip


_OVERLAY = ("(() => { const i = document.getElementById('dx-overlay');"
            " return i && i.complete && i.naturalWidth > 0"
            " && [i.naturalWidth, i.getBoundingClientRect().width,"
            " document.documentElement.clientWidth]; })()")  # fmt: skip


@pytest.mark.browser
def test_a_record_is_diagnosed_on_a_page_of_its_own(tmp_path):
    chromium()
    # a record of the shipped diagnoser's domain (simulated, the four channels), made before
    # the browser starts so that the page waits for the diagnosis, not for a compiler
    nc = example_record(tmp_path, revolutions=4.0)
    bad = tmp_path / "record.xyz"
    bad.write_text("not a record\n")
    server = tempfile.gettempdir()
    with served_page(build_app(None), tmp_path) as (page, port, _):
        # 1. the simulation page first; the tab opens the diagnosis page and names it
        page.call("Page.navigate", url=f"http://127.0.0.1:{port}/")
        page.wait(_shown("simulate-page"))
        assert not page.js(_shown("diagnose-tab"))
        page.click(_el("tab-diagnose"))
        page.wait(f"{_shown('diagnose-tab')} && !{_shown('simulate-page')}")
        assert page.wait("location.hash") == "#diagnose"
        # 2. a record chosen in the file input: named, then diagnosed
        page.set_file("#dx-upload input[type=file]", nc)
        assert page.wait(f"{_el('dx-file')}.innerText") == f"record: {nc.name}"
        page.click(_el("dx-run"))
        page.wait(f"!!{_el('dx-probabilities')}", timeout=300)
        probs = {c[0]: float(c[1]) for c in page.js(_rows("dx-probabilities"))}
        assert len(probs) >= 2 and abs(sum(probs.values()) - 1) <= 0.005 * len(probs)
        top = page.js(f"{_el('dx-label')}.innerText").split("Most probable:")[1].split()[0]
        assert probs[top] == max(probs.values())
        assert "interval" in page.js(f"{_el('dx-severity')}.innerText")
        evidence = page.js(_rows("dx-evidence"))
        assert len(evidence) >= 4 and all(len(r) == 3 and r[0] and r[1] for r in evidence)
        assert "impacts per revolution" in [r[0] for r in evidence]
        assert sum(bool(r[2]) for r in evidence) >= 4  # what each item means
        channels = dict(page.js(_rows("dx-channels")))
        assert channels["acceleration"] == "accel_guide" and channels["tacho"] == "tacho"
        assert channels["head-end pressure"] == "p_head_sensor"
        natural, width, page_width = page.wait(_OVERLAY, timeout=120)
        assert natural > 300 and width >= 0.8 * page_width, (width, page_width)
        html = page.js("document.documentElement.outerHTML")
        assert server not in html and str(tmp_path) not in html
        # 3. the same record read at a crank speed the diagnoser was not trained for
        assert page.type_at(_el("dx-speed"), "600 rpm") == "600 rpm"
        page.click(_el("dx-run"))
        page.wait(f"!!{_el('dx-refusal')}", timeout=300)
        refusal = page.js(f"{_el('dx-refusal')}.innerText")
        assert refusal.startswith("Diagnosis withheld") and "crank speed" in refusal
        assert page.js(f"getComputedStyle({_el('dx-refusal')}).borderTopColor") == (
            "rgb(176, 0, 32)"
        )  # red
        assert not page.js(f"!!{_el('dx-probabilities')} || !!{_el('dx-overlay')}")
        assert dict(page.js(_rows("dx-channels")))["constant speed"] == "600 rpm"
        # 4. a file of a type the page cannot read: told, with the allowed types
        page.type_at(_el("dx-speed"), "")
        page.set_file("#dx-upload input[type=file]", bad)
        page.wait(f"{_el('dx-file')}.innerText.includes('record.xyz')")
        page.click(_el("dx-run"))
        told = page.wait(f"!!{_el('dx-error')} && {_el('dx-error')}.innerText", timeout=120)
        assert ".csv" in told and ".nc" in told and server not in told
        # 5. the address opens the page
        page.call("Page.navigate", url="about:blank")
        page.wait("document.readyState === 'complete' && location.href === 'about:blank'")
        page.call("Page.navigate", url=f"http://127.0.0.1:{port}/#diagnose")
        page.wait(f"{_shown('diagnose-tab')} && !{_shown('simulate-page')}")
