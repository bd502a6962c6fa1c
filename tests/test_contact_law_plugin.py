"""A contact law of the pin joints from a user's file (issue 30, items 5 and 6): the laws of
``tests/plugin_components.py`` (the test suite's own file, recipdyn untouched) chosen by
``contact_law = file.py:OBJ``, run by the contact joints' generated glue with their own
slice of the parameter vector, through the model, the energy balance, simulate, analyze, a
rerun from the record and a sweep."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from scipy.integrate import solve_ivp

from recipdyn.cli import main
from recipdyn.errors import ParameterError
from recipdyn.integrate import integrate
from recipdyn.model.joints.contact import delivered_restitution, hysteresis_factor
from recipdyn.model.joints.pins import I_WIN, I_WLOSS
from recipdyn.model.registry import get_model

HERE = Path(__file__).parent
FILE = HERE / "plugin_components.py"
LN = f"{FILE.resolve()}:LANKARANI"
KV = f"{FILE.resolve()}:KELVIN_VOIGT"
M = get_model("compressor")


def _run(values, t_end, n=2001):
    s = M.system(values)
    t = np.linspace(0.0, t_end, n)
    return s, integrate(s, M.initial_state(values), (0.0, t_end), t_eval=t)


@pytest.mark.parametrize("pins", [
    dict(crank_joint="contact"),
    dict(crank_joint="lubricated", crosshead_joint="contact", rc_crosshead=2e-4, friction=0.1,
         friction_law="tanh", v0=0.01, v1=0.02),
])  # fmt: skip
def test_lankarani_nikravesh_from_a_file_gives_the_builtins_trajectory_to_the_bit(pins):
    """Hypothesis: the glue of a user's law differs from the built-in glue only in the three
    calls the law makes (normal force, elastic part, friction left built-in here). The file's
    law writes Lankarani-Nikravesh with the same floating-point operations in the same order
    (``K delta sqrt(delta) (1 + chi delta' / v-)``, chi = 3 (1 - e^2) / 4 packed in the
    law's slice), so half a revolution with impacts (at one pin; an oil film at the crank pin
    and dry contact with tanh friction at the crosshead pin) gives the same trajectory, event
    times and step count to the bit, and the recorded energy (the law's potential, the same
    formula evaluated in compiled code instead of numpy) to rounding."""
    base = dict(omega=150.0, load_amplitude=2e4, restitution=0.9, **pins)
    v0 = M.parameters(base)
    v1 = M.parameters({**base, "contact_law": LN, "ln_restitution": 0.9})
    assert v1["contact_law"] == LN and v1["ln_restitution"] == 0.9
    T = M.period(v0)
    s0, a = _run(v0, 0.5 * T, 201)
    s1, b = _run(v1, 0.5 * T, 201)
    assert s1.params.size == s0.params.size + 1  # the law's slice: chi
    assert a.t_events.size >= 3  # impacts happen (or the law would not be exercised)
    assert np.array_equal(a.y, b.y) and np.array_equal(a.t_events, b.t_events)
    assert a.nfev == b.nfev
    e0, e1 = M.outputs(v0, a.t, a.y), M.outputs(v1, b.t, b.y)
    np.testing.assert_allclose(e1["energy"].values, e0["energy"].values, rtol=1e-13)
    assert np.array_equal(e1["normal_force"].values, e0["normal_force"].values)


@pytest.mark.filterwarnings("ignore::recipdyn.errors.LawRangeWarning")
def test_a_users_law_acts_with_a_motor_too():
    """Hypothesis: with a motor (the crank free) the glue runs the file's law, not the
    built-in one: the kernels' joints' forces (``joints_at``, called with the crank's state)
    are those of the joints' module written for the law (its ``law_normal`` the file's), and a
    run with
    the Kelvin-Voigt law (a spring-dashpot: another normal force at every contact) differs
    from the built-in law's run through the same impacts by a large part of the crank-pin
    eccentricity's swing (a model that ignored the law would give the same run to the
    bit)."""
    base = dict(crank_joint="contact", omega=150.0, load_amplitude=2e4, drive="motor",
                motor="constant")  # fmt: skip
    v0 = M.parameters(base)
    v1 = M.parameters({**base, "contact_law": KV, "kv_stiffness": 1e10, "kv_damping": 3e5})
    T = M.period(v0)
    _, a = _run(v0, 0.25 * T, 201)
    s1, b = _run(v1, 0.25 * T, 201)
    glue = sys.modules[s1.rhs.py_func.__module__]
    joints = sys.modules[glue.joints_at.py_func.__module__]  # the module of the law's joints
    assert joints.law_normal.py_func.__name__ == "kv_normal"  # the file's law, not the built-in
    assert a.t_events.size >= 2  # impacts happen (or the law would not be exercised)
    ex0, ex1 = a.y[:, 0], b.y[:, 0]
    assert np.abs(ex1 - ex0).max() > 0.01 * np.ptp(ex0) > 0.0


def _impact(law: dict, t_end: float) -> float:
    """The restitution one impact at the crank pin delivers: the journal centred, the bearing
    (rod and crosshead) moving at 1 m/s along the rod, no gas force, no gravity, the crank
    nearly still; the rebound's radial velocity once the journal has left the wall."""
    v = M.parameters(dict(crank_joint="contact", g=0.0, d=0.0, omega=1e-3, load_amplitude=0.0,
                          e0_ratio=0.0, edot0_x=1.0, **law))  # fmt: skip
    _, sol = _run(v, t_end, 4001)
    assert sol.t_events.size == 1  # one impact
    y = sol.y[1:]
    rho = np.hypot(y[:, 0], y[:, 1])
    after = np.flatnonzero(rho > v["rc"]).max() + 5  # in flight again
    assert after < len(y) - 1
    return -(y[after, 0] * y[after, 4] + y[after, 1] * y[after, 5]) / rho[after]


def test_a_spring_dashpot_law_delivers_its_own_restitution():
    """Hypothesis: the model runs the file's law at the pin. A single impact (the rod and the
    crosshead, m = m2 + m3 = 50 kg, moving along the rod at 1 m/s into the crank pin's wall)
    delivers the restitution of a 1-DOF impact under the law: for the built-in
    Lankarani-Nikravesh law (e = 0.9) its closed form, 0.9132 (independent of the mass); for
    the Kelvin-Voigt law ``k delta + c delta'`` clamped at 0, with damping ratio
    c / (2 sqrt(k m)) = 0.21, the 1-DOF impact integrated here by scipy: 0.5548. A model that
    ignored the file's law would give 0.9132 for both. The mechanism's other forces are
    nil (no gas force, no gravity, the crank turning 1e-3 rad/s: centripetal terms ~1e-7 of
    the impact's); measured agreement 1e-8 (the delta^1.5 onset, as in test_contact's single
    impacts) and 2e-10: the bound 1e-6 is test_contact's for the same integration."""
    e_ln = _impact({}, 2.5e-3)
    assert e_ln == pytest.approx(delivered_restitution(
        hysteresis_factor("lankarani-nikravesh", 0.9)), abs=1e-6)  # fmt: skip
    k, c, m = 1e10, 3e5, 50.0
    e_kv = _impact({"contact_law": KV, "kv_stiffness": k, "kv_damping": c}, 2.5e-3)

    def rhs(t, y):
        return [y[1], -max(k * y[0] + c * y[1], 0.0) / m]

    def leaves(t, y):
        return y[0]

    leaves.terminal, leaves.direction = True, -1
    one = solve_ivp(rhs, (0.0, 1.0), [0.0, 1.0], method="DOP853", events=leaves, rtol=1e-12,
                    atol=1e-15, first_step=1e-10)  # fmt: skip
    expected = -one.y_events[0][0][1]
    assert 0.5 < expected < 0.6
    assert e_kv == pytest.approx(expected, abs=1e-6)
    assert e_kv < e_ln - 0.3  # the direction the law's damping implies


@pytest.mark.parametrize("pins", [
    dict(crank_joint="contact"),
    dict(crank_joint="contact", crosshead_joint="contact", rc_crosshead=2e-4),
])  # fmt: skip
def test_the_energy_balance_closes_with_a_users_law(pins):
    """E + U - E0 - U0 = W_in - W_loss (test_contact's balance), with U the law's elastic
    energy (here the integral of its ``elastic``: the file gives no potential) and W_loss
    from ``(F_n - elastic) delta' - F_t v_t``. Integrated with the state, the balance closes
    to the integration error: below 1e-7 of the energy scale (test_contact's bound; measured
    ~1e-11). The law dissipates (W_loss > 0) across impacts."""
    v = M.parameters(dict(omega=150.0, load_amplitude=2e4, contact_law=KV, **pins))
    T = M.period(v)
    _, sol = _run(v, 2.0 * T, 2001)
    E = M.outputs(v, sol.t, sol.y)["energy"].values
    bal = E - E[0] - (sol.y[:, I_WIN] - sol.y[:, I_WLOSS])
    assert np.abs(bal).max() < 1e-7 * np.abs(E).max()
    assert sol.y[-1, I_WLOSS] > 0.0 and sol.t_events.size >= 2


def test_the_complex_step_jacobian_holds_with_a_users_law():
    """The joints' Jacobian is the complex step of the glue's right-hand side, the file's law
    included (its functions take complex arguments): against the glue's fourth-order central
    differences at states in contact and in flight (bound 1e-3 of each column's size, as in
    test_contact)."""
    v = M.parameters(dict(crank_joint="contact", omega=150.0, load_amplitude=2e4,
                          contact_law=KV, kv_stiffness=1e10, kv_damping=3e5))  # fmt: skip
    s = M.system(v)
    T = M.period(v)
    _, sol = _run(v, T, 25)
    fd = get_model("compressor-contact").kernels(v).fd_jac  # (the implementation's glue)
    phases = set()
    for t, y in zip(sol.t[1:], sol.y[1:], strict=True):
        J = s.jacobian(t, y)
        Jfd = np.empty_like(J)
        fd(t, y, s.params, Jfd)
        col = np.abs(Jfd).max(axis=0)
        assert np.all(np.abs(J - Jfd)[:, :10] <= 1e-3 * col[:10] + 1e-300)
        phases.add(math.hypot(y[0], y[1]) > v["rc"])
    assert phases == {True, False}


def test_a_law_is_refused_where_it_cannot_act_or_is_not_a_law():
    """One line each: a law on a configuration without a contact joint (naming the selector
    that enables it), an object that is not a contact law, a law without a required role,
    a parameter of the law's that the model already has."""
    with pytest.raises(ParameterError, match="crank_joint or crosshead_joint = 'contact'"):
        M.parameters(contact_law=KV)  # the massless link
    with pytest.raises(ParameterError, match="both pins ideal.*crank_joint or crosshead_joint"):
        M.parameters(guide="clearance", crank_joint="ideal", contact_law=KV)
    with pytest.raises(ParameterError, match="is a motor component, not a contact_law"):
        M.parameters(crank_joint="contact", contact_law=f"{FILE}:LINEAR")
    with pytest.raises(ParameterError, match="provides no elastic kernel"):
        M.parameters(crank_joint="contact", contact_law=f"{FILE}:NO_ELASTIC")
    with pytest.raises(ParameterError, match="kv_stiffness"):
        M.parameters(crank_joint="contact", contact_law=KV, kv_stiffness=-1.0)


def test_a_users_law_through_simulate_analyze_rerun_and_sweep(tmp_path, monkeypatch, capsys):
    """A law from the test suite's file through the command line: simulate (the record
    stores the law's spec, absolute, and its parameters with units), analyze (Benettin's
    exponents on the glue with the file's law) and ``simulate -c`` from another folder (the
    same samples), and a 2-point sweep of the law's own parameter in worker processes whose
    peak at the simulated point is the simulated run's (the same samples: chunks never
    change results) and differs at the other (at 150 rad/s with a tenth of the paper's load:
    impacts, where the restitution acts). (The Lankarani-Nikravesh law of the file:
    Benettin's method on the Kelvin-Voigt law's sustained contact is far slower, see
    docs/components.md.)"""
    a, b = tmp_path / "a.nc", tmp_path / "b.nc"
    monkeypatch.chdir(HERE)
    run = ["-n", "1", "--fs", "20 kHz", "--no-progress"]
    assert main(["simulate", "--model", "compressor", "--set", "crank_joint=contact",
                 "--set", "contact_law=plugin_components.py:LANKARANI",
                 "--set", "ln_restitution=0.8", "--set", "omega=150", "--set",
                 "load_amplitude=2e4", *run, "-o", str(a), "--no-figure"]) == 0  # fmt: skip
    da = xr.open_dataset(a)
    assert da.attrs["param_contact_law"] == LN
    assert da.attrs["param_ln_restitution"] == 0.8
    monkeypatch.chdir(tmp_path)
    assert main(["analyze", str(a), "-o", str(tmp_path / "an"), "--section-points", "3",
                 "--lyap-revolutions", "0.2"]) == 0  # fmt: skip
    summary = json.loads((tmp_path / "an" / "summary.json").read_text())
    assert summary["poincare"]["points"] == 3 and "lyapunov_equations" in summary
    assert main(["simulate", "-c", str(a), "-o", str(b), "--no-figure", "--no-progress"]) == 0
    db = xr.open_dataset(b)
    for k in da.data_vars:
        assert np.array_equal(da[k].values, db[k].values), k
    capsys.readouterr()
    assert main(["sweep", "--set", "crank_joint=contact", "--set", f"contact_law={LN}",
                 "--set", "omega=150", "--set", "load_amplitude=2e4",
                 "-p", "ln_restitution=0.8,0.5", "-m", "peak", "--revolutions", "1",
                 "--transient", "0", "--fs", "20 kHz", "--workers", "2",
                 "-o", str(tmp_path / "sw"), "--no-progress"]) == 0  # fmt: skip
    from recipdyn.sweep import open_sweep

    sw = open_sweep(tmp_path / "sw" / "sweep.zarr").load()
    assert list(sw["error"].values) == ["", ""]
    assert sw.attrs["param_contact_law"] == LN
    assert sw["peak_a"].values[0] == pytest.approx(float(np.abs(da.a.values).max()), rel=1e-12)
    assert sw["peak_a"].values[0] != sw["peak_a"].values[1]
