"""Warnings reach a command-line user as one line each, once (issue 44, item 5).

Raw Python warnings (category, file, line and the source line) appeared in the middle of
`make run`'s progress bars, printed by the worker processes of the reproduction; the
diagnoser's healthy machine printed a paragraph-long `LawRangeWarning` on every run. Every
warning now goes through the command line's own channel (`warnings_said_once`: ``warning:
TEXT`` on one line, each text once per command, written by tqdm so a bar stays whole), and a
worker's warnings come back with its result (`recipdyn.parallel.run_unordered`).
"""

from __future__ import annotations

import warnings

import numpy as np
import xarray as xr

from recipdyn.cli import main, warnings_said_once
from recipdyn.parallel import run_unordered


class _NoSignal:
    def check(self) -> None:
        pass


def _warns(i: int) -> int:
    """A task that warns twice in its worker (the same text each time)."""
    for _ in range(2):
        warnings.warn("the worker's warning,\n  over two lines", UserWarning, stacklevel=1)
    return i * i


def test_a_workers_warnings_come_back_to_the_command_once(capfd):
    """Four tasks on two worker processes warn alike: nothing is written by the workers, the
    command says one line."""
    results: list[int] = []
    with warnings_said_once():
        run_unordered(_warns, range(4), 2, results.append, _NoSignal())
    assert sorted(results) == [0, 1, 4, 9]
    err = capfd.readouterr().err.splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(
        "warning: the worker's warning, over two lines (UserWarning in tests/test_cli_warnings.py:"
    ), err


def test_a_workers_warning_is_raised_again_in_the_library():
    """Without the command line (the Python API), the coordinating process raises the
    workers' warnings as warnings of its own, with their origin (file and line)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run_unordered(_warns, range(2), 2, lambda r: None, _NoSignal())
    texts = {str(w.message) for w in caught}
    assert texts == {"the worker's warning,\n  over two lines"}
    assert all(w.filename == __file__ for w in caught)


def test_a_commands_warnings_are_one_line_each_and_said_once(monkeypatch, capsys):
    """A command whose library call warns three times, a library's warning among them: one
    line each distinct text, no source line, the library's category and origin named."""
    import recipdyn.model.registry as registry

    real = registry.model_names

    def warned():
        for _ in range(3):
            warnings.warn("a long\n   explanation", UserWarning, stacklevel=1)
        np.log(np.zeros(1))  # numpy's RuntimeWarning: divide by zero
        return real()

    monkeypatch.setattr(registry, "model_names", warned)
    with np.errstate(divide="warn"):
        assert main(["models"]) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert err[0].startswith("warning: a long explanation (UserWarning in tests/test_cli_warnings")
    assert err[1].startswith("warning: divide by zero encountered in log (RuntimeWarning in ")
    assert len(err) == 2 and not any("np.log(" in line or "warnings.warn(" in line for line in err)


def test_the_healthy_machines_law_range_warning_is_right_and_short():
    """The diagnoser's healthy machine (0.1 mm at both pins) under the paper's load
    penetrates 42 um (docs/contact.md's table): a contact arc of +-45 deg, beyond the
    point-contact law's +-28.6 deg, so the warning is right. It is one line of under 250
    characters that names each pin and its arc (it was ~600 characters)."""
    from recipdyn.model.components.contact_model import HERTZ_ARC_LIMIT_DEG, overlap_half_angle
    from recipdyn.model.registry import get_model

    assert overlap_half_angle(0.05, 1e-4, 4.17e-5) > HERTZ_ARC_LIMIT_DEG
    m = get_model("compressor-contact")
    v = m.parameters({"crosshead_joint": "contact", "rc": 1e-4, "rc_crosshead": 1e-4})
    ds = xr.Dataset({"delta": ("time", [0.0, 4.17e-5]), "delta_crosshead": ("time", [0.0, 1e-6])})
    msg = m.law_range(v, ds)
    assert "\n" not in msg and len(msg) < 250, msg
    assert "the crank pin (+-45" in msg and "crosshead pin" not in msg  # (1 um: in range)
    assert "28.6 deg" in msg and "Johnson 1985" in msg
