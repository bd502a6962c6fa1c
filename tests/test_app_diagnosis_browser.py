"""The app's diagnosis section in a real headless Chromium (the Chrome DevTools Protocol, as
``tests/test_app.py``): a NetCDF record chosen in the file dialog is diagnosed on the page
(the class probabilities, the evidence, the overlay image decoded by the browser); the same
record given a crank speed outside the shipped diagnoser's domain is refused on the page, in
red, with the reason; a file of a type the page cannot read is told beside the button."""

import pytest

from _cdp import chromium, served_page
from recipdyn.app import build_app
from recipdyn.app.diagnosis import example_record

_RESULT = "(document.getElementById('dx-result') || {innerText: ''}).innerText"
_OVERLAY = ("(() => { const i = document.querySelector('#dx-result img');"
            " return i && i.complete && i.naturalWidth; })()")  # fmt: skip


def _input(id_: str) -> str:
    return f"document.getElementById('{id_}')"


@pytest.mark.browser
def test_a_record_dropped_on_the_page_is_diagnosed_or_refused(tmp_path):
    chromium()
    # a record of the shipped diagnoser's domain (simulated, the four channels), made before
    # the browser starts so that the page waits for the diagnosis, not for a compiler
    nc = example_record(tmp_path, revolutions=4.0)
    bad = tmp_path / "record.xyz"
    bad.write_text("not a record\n")
    with served_page(build_app(None), tmp_path) as (page, port, _):
        page.call("Page.navigate", url=f"http://127.0.0.1:{port}/")
        page.wait(f"{_input('dx-upload')} !== null")
        # 1. choose the record in the file input: the page names it, then diagnoses it
        page.set_file("#dx-upload input[type=file]", nc)
        assert page.wait(f"{_input('dx-file')}.innerText") == f"record: {nc.name}"
        page.click(_input("dx-run"))
        text = page.wait(f"{_RESULT}.startsWith('diagnosis:') && {_RESULT}", timeout=300)
        first = text.splitlines()[0]  # "diagnosis: ring_leak (p = 1.00); ring_leak 1.00, ..."
        top = first.split()[1]
        probs = dict(x.rsplit(" ", 1) for x in first.split("; ", 1)[1].split(", "))
        assert top in probs and float(probs[top]) == max(map(float, probs.values()))
        assert sum(map(float, probs.values())) <= 1.0 + 0.01 * len(probs)  # rounded to 0.01
        assert "impacts:" in text and "severity" in text  # the evidence, the severity
        assert "head-end pressure shape" in text  # the pressure channels the page named
        assert page.wait(_OVERLAY, timeout=120) > 300  # the overlay PNG, decoded
        colour = page.js(f"getComputedStyle({_input('dx-result')}.firstChild).color")
        assert colour != "rgb(176, 0, 32)"  # an answer, not a refusal
        # 2. the same record read at a crank speed the diagnoser was not trained for
        assert page.type_at(_input("dx-speed"), "600 rpm") == "600 rpm"
        page.click(_input("dx-run"))
        refusal = page.wait(f"{_RESULT}.includes('crank speed') && {_RESULT}", timeout=300)
        assert "refused" in refusal.lower() or "outside" in refusal.lower(), refusal
        assert page.js(f"getComputedStyle({_input('dx-result')}.firstChild).color") == (
            "rgb(176, 0, 32)"
        )  # red
        assert page.js("document.querySelectorAll('#dx-result img').length") == 0
        # 3. a file of a type the page cannot read: told, with the allowed types
        page.type_at(_input("dx-speed"), "")
        page.set_file("#dx-upload input[type=file]", bad)
        page.wait(f"{_input('dx-file')}.innerText.includes('record.xyz')")
        page.click(_input("dx-run"))
        told = page.wait(f"{_RESULT}.includes('allowed') && {_RESULT}", timeout=120)
        assert ".csv" in told and ".nc" in told
