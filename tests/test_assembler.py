"""The assembler (issue 43): a machine description resolved into kernels with a named layout.

* the layout names every value: each part's slice and each named entry's index, and the
  packed vector holds each throw's own values where its names say;
* the generated module is the template verbatim with its bindings block replaced (names and
  constants only), and a template's block binds exactly the roles and constants it names;
* a machine file of one throw is the compressor: the same values, the same run to the bit;
* several throws on one crankshaft: the crank's equation from each throw's contribution
  equals a combined symbolic derivation of two throws; two identical throws at 0 and 360 deg
  are one throw with doubled masses and forces; every throw's power balance holds at random
  states and the whole machine's energy balance over a run;
* the command line: ``--machine FILE`` runs, draws each throw by crank angle, takes
  namespaced ``--set``, and refuses a bad machine in one line.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import recipdyn
from recipdyn.cli import main
from recipdyn.errors import ModelValidityWarning, ParameterError
from recipdyn.model.machine import Machine, Shaft, Stage, Throw, read_machine

ROOT = Path(__file__).resolve().parents[1]
TWO_THROW = ROOT / "examples" / "machines" / "two_throw.toml"


def _model(machine: Machine):
    from recipdyn.model.assembler.model import MachineModel

    return MachineModel(machine)


def _two(drive="motor", load="paper", phases=(0.0, math.pi), extra=(), motor="induction",
         **shaft):  # fmt: skip
    """Two throws of the paper's compressor, the second one with other geometry and masses
    (so that a slice read at the wrong offset shows)."""
    t1 = Throw("throw1", load=load, params=(("phase", phases[0]), ("rc", 1e-3), *extra))
    t2 = Throw("throw2", load=load, params=(("phase", phases[1]), ("rc", 0.7e-3), ("r", 0.11),
                                            ("l", 0.55), ("m2", 24.0), ("m3", 35.0),
                                            ("J2", 0.7), ("d", 0.5e-3), *extra))  # fmt: skip
    return Machine("test-two", shaft=Shaft(drive, motor, tuple(shaft.items())),
                   throws=(t1, t2), stages=(Stage(),))  # fmt: skip


def test_the_layout_names_every_value_and_the_vector_holds_each_throws_own():
    """``layout.state["throw2.theta_c"]`` and ``layout.params["throw2.rc"]``: each name is
    one index, each part one slice, and the packed value at a throw's name is that throw's
    value (the second throw's geometry differs from the first's in every mechanism entry
    the test sets)."""
    m = _model(_two())
    v = m.parameters()
    c = m.configuration(v)
    st, pv = c.layout.state, c.layout.params
    assert st.names == ("throw1.theta_c", "throw1.thetadot_c", "throw2.theta_c",
                        "throw2.thetadot_c", "theta1", "omega1", "W_motor", "throw1.W_gas",
                        "throw2.W_gas")  # fmt: skip
    assert st["throw2.theta_c"] == 2 and st["throw2.mechanism"] == slice(2, 4)
    for name in ("rc", "r", "l", "m2", "m3", "J2", "d", "phase"):
        for t in ("throw1", "throw2"):
            assert c.params[pv[f"{t}.{name}"]] == v[f"{t}.{name}"], (t, name)
    assert v["throw2.rc"] != v["throw1.rc"] and v["throw2.phase"] == pytest.approx(math.pi)
    assert c.params[pv["shaft.drive"]][0] == v["shaft.J_drive"]
    with pytest.raises(KeyError, match="neither an entry nor a part"):
        st["throw3.theta_c"]
    assert c.aux_states == 3 and c.passive([{"rc": 1e-3}, {"rc": 1e-3}]) == (6, 7, 8)


def test_a_generated_module_is_its_template_with_names_and_constants_only():
    """The text of a configuration's module equals its template outside the bindings block,
    and the block holds imports and constants only: nothing of a body is edited. A block
    that lacks a name the template binds, or gives one it does not, is refused."""
    from recipdyn.model.assembler import generate

    m = _model(_two(drive="prescribed"))
    mod = m.configuration(m.parameters()).kernels
    text = Path(mod.__file__).read_text()
    template = (generate.TEMPLATES / "prescribed.py").read_text()
    i, j = template.index(generate.BEGIN), template.index(generate.END) + len(generate.END)
    a, b = text.index(generate.BEGIN), text.index(generate.END) + len(generate.END)
    assert text[:a] == template[:i] and text[b:] == template[j:]
    roles, consts = generate.template_names("prescribed")
    assert "N_THROWS = np.int64(2)" in text[a:b] and {"crank", "throw_acc"} <= roles
    with pytest.raises(ValueError, match="do not match its bindings"):
        generate.bindings("prescribed", {}, {k: 0 for k in consts})


@pytest.mark.parametrize("drive", ["prescribed", "motor"])
def test_a_templates_own_block_binds_its_reference_configuration(drive):
    """Each template is a valid module as it stands: its block binds the reference
    configuration (one throw of the paper's compressor; the induction motor), exactly the
    roles and constants the assembler binds for it, so the template that is linted and read
    is the code a configuration runs."""
    from recipdyn.model.registry import get_model

    m = get_model("compressor")
    impl, own = m._split(m.parameters({"drive": drive}))  # (its route's machine)
    template, roles, constants, _, _ = impl.configuration(own).bindings()
    got_roles, got_consts = _block(template)
    assert got_roles == roles
    _same_constants(got_consts, constants)


def _block(template: str) -> tuple[dict, dict]:
    """The roles ``name -> (module, function)`` and the constants a template's own block
    binds."""
    import ast

    from recipdyn.model.assembler import generate

    text = (generate.TEMPLATES / f"{template}.py").read_text()
    block = text[text.index(generate.BEGIN) : text.index(generate.END)]
    roles, consts = {}, {}
    for node in ast.parse(block).body:
        if isinstance(node, ast.ImportFrom):
            roles.update({a.asname or a.name: (node.module, a.name) for a in node.names})
        else:
            consts[node.targets[0].id] = eval(ast.unparse(node.value), {"np": np})
    return roles, consts


def _same_constants(got: dict, want: dict) -> None:
    assert got.keys() == want.keys()
    for k, v in want.items():
        assert np.array_equal(np.asarray(got[k]), np.asarray(v)), k


def test_the_contact_templates_bind_their_reference_configuration():
    """The joints' and the contact kernels' templates as they stand bind the reference
    configuration of `compressor-contact` (the crank pin worn, the built-in law, Ambrósio's
    friction, the paper's load, the crank prescribed, the guide rigid): the names and
    constants the model binds for it (the joints' functions from the template of the joints
    itself, where the model writes a module per law)."""
    from recipdyn.model.components import contact_model as cm
    from recipdyn.model.components.load import PAPER
    from recipdyn.model.registry import get_model

    v = get_model("compressor-contact").parameters()
    roles, consts, _, _ = cm.joints_bindings(None, cm.friction_part(v), "ambrosio_friction")
    got_roles, got_consts = _block("joints")
    assert got_roles == roles
    _same_constants(got_consts, consts)
    jm = "recipdyn.model.assembler.templates.joints"
    roles, consts, _ = cm.contact_bindings(jm, v["clearance_joints"], PAPER, False, 0, None, 0)
    got_roles, got_consts = _block("contact")
    assert got_roles == roles
    _same_constants(got_consts, consts)


def test_a_one_throw_machine_file_is_the_compressor(tmp_path):
    """A machine file of one throw keeps the compressor's names, validates to the values
    ``--model compressor`` gives for the same settings, and runs the same kernels: the same
    record to the bit (the same arithmetic, one path)."""
    f = tmp_path / "one.toml"
    f.write_text('[shaft]\nomega = "25 rad/s"\n\n[[throw]]\nload = "cycle"\nrc = "1.5 mm"\n')
    from recipdyn.model.registry import get_model

    machine = get_model(str(f))
    values = machine.parameters()
    assert values["rc"] == pytest.approx(1.5e-3) and values["omega"] == 25.0
    ref = get_model("compressor").parameters({"load": "cycle", "rc": 1.5e-3, "omega": 25.0})
    assert {k: values[k] for k in ref if k in values} == {k: ref[k] for k in ref if k in values}
    kw = dict(revolutions=0.1, fs=4000.0)
    a = _simulate(model=machine, **kw)
    b = _simulate(model="compressor", params={"load": "cycle", "rc": 1.5e-3,
                                                      "omega": 25.0}, **kw)  # fmt: skip
    for k in ("x", "a", "theta_c", "gas_force", "contact_force"):
        assert np.array_equal(a[k].values, b[k].values), k


def _free_system_two_throws():
    """The combined Lagrangian of two throws on one crankshaft, derived by sympy: coordinates
    (theta1, theta_c1, theta_c2), each throw's energies from
    `recipdyn.model.derivation._free_crank_energy` with its own symbols and phase, the
    drive's inertia once, the motor's torque on theta1 and each gas force doing the virtual
    work F_k dx3_k. Returns a function of the state, the parameters and the inputs giving
    (theta1'', theta_c1'', theta_c2'')."""
    import sympy as sp

    from recipdyn.model import derivation as dv

    T1, V1, x31 = dv._free_crank_energy(False)
    names = [dv.r, dv.rs, dv.l, dv.ls, dv.m1, dv.m2, dv.m3, dv.J1, dv.J2, dv.g, dv.rc, dv.d]
    th1, thd1 = dv.th1, dv.th1d
    q = sp.symbols("thc1 thc2", real=True)
    qd = sp.symbols("thcd1 thcd2", real=True)
    phi2, Jd, Tm, F1, F2 = sp.symbols("phi2 J_d T_m F1 F2", real=True)
    p2 = sp.symbols("r_2 rs_2 l_2 ls_2 m1_2 m2_2 m3_2 J1_2 J2_2 g_2 rc_2 d_2", real=True)
    sub1 = {dv.thc: q[0], dv.thcd: qd[0], dv.Jd: 0}
    sub2 = {
        dv.thc: q[1],
        dv.thcd: qd[1],
        dv.Jd: 0,
        th1: th1 + phi2,
        **dict(zip(names, p2, strict=True)),
    }
    T = T1.subs(sub1) + T1.subs(sub2) + Jd * thd1**2 / 2
    V = V1.subs(sub1) + V1.subs(sub2)
    x3a, x3b = x31.subs(sub1), x31.subs(sub2)
    L = T - V
    coords, rates = (th1, *q), (thd1, *qd)
    Q = [Tm + F1 * sp.diff(x3a, th1) + F2 * sp.diff(x3b, th1), F1 * sp.diff(x3a, q[0]),
         F2 * sp.diff(x3b, q[1])]  # fmt: skip
    dL = [sp.diff(L, v) for v in rates]
    M = sp.Matrix(3, 3, lambda i, j: sp.diff(dL[i], rates[j]))
    b = sp.Matrix([Q[i] + sp.diff(L, coords[i])
                   - sum(sp.diff(dL[i], coords[j]) * rates[j] for j in range(3))
                   for i in range(3)])  # fmt: skip
    args = [*coords, *rates, *names, *p2, phi2, Jd, Tm, F1, F2]
    fM = sp.lambdify(args, M, "numpy", cse=True)
    fb = sp.lambdify(args, b, "numpy", cse=True)
    return lambda *a: np.linalg.solve(np.array(fM(*a), dtype=float),
                                      np.array(fb(*a), dtype=float).ravel())  # fmt: skip


def test_the_crank_equation_from_each_throws_share_equals_a_combined_derivation(rng):
    """Two throws of different geometry at 0 and 137 deg on the motor: the assembled
    right-hand side (each throw's share of the crank's equation, its clearance angle affine in
    the crank's acceleration) against the whole machine's equations derived at once by sympy
    and solved by LAPACK, at 20 random states. Both are exact; they differ by rounding,
    bounded by the mass matrix's condition times eps: its entries run from m rc**2 ~ 3e-5
    kg m**2 (the clearance coordinates) to J_drive = 3e3, a condition up to ~1e8, so 1e-8 of
    the largest acceleration is allowed (measured 5e-16)."""
    from recipdyn.model.components.drive_kernels import induction_torque
    from recipdyn.model.mechanism.link import MECHANISM

    phase2 = math.radians(137.0)
    model = _model(_two(phases=(0.0, phase2)))
    v = model.parameters()
    c = model.configuration(v)
    st, pv = c.layout.state, c.layout.params
    solve = _free_system_two_throws()
    locals_ = model.throws(v)
    mech = [[float(loc[k]) for k in MECHANISM] for loc in locals_]
    from recipdyn.model.components.load import force_series

    worst = 0.0
    for _ in range(20):
        y = model.initial_state(v)
        y[st["theta1"]] = rng.uniform(0, 2 * math.pi)
        y[st["omega1"]] = rng.uniform(15.0, 25.0)
        for t in ("throw1", "throw2"):
            y[st[f"{t}.theta_c"]] += rng.normal(0, 0.3)
            y[st[f"{t}.thetadot_c"]] = rng.normal(0, 20.0)
        out = np.empty(len(y))
        c.kernels.rhs(0.0, y, c.params, out)
        th1, w1 = y[st["theta1"]], y[st["omega1"]]
        F = [float(force_series(loc, th1 + loc["phase"])) for loc in locals_]
        Tm = induction_torque(w1, c.params, pv.start("shaft.motor"))
        ref = solve(th1, y[st["throw1.theta_c"]], y[st["throw2.theta_c"]], w1,
                    y[st["throw1.thetadot_c"]], y[st["throw2.thetadot_c"]], *mech[0], *mech[1],
                    phase2, v["shaft.J_drive"], Tm, F[0], F[1])  # fmt: skip
        got = np.array([out[st["omega1"]], out[st["throw1.thetadot_c"]],
                        out[st["throw2.thetadot_c"]]])  # fmt: skip
        err = np.abs(got - ref) / np.max(np.abs(ref))
        worst = max(worst, float(err.max()))
    assert worst < 1e-8, worst


def _simulate(**kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelValidityWarning)
        return recipdyn.simulate(**kw)


def test_two_identical_throws_at_0_and_360_deg_are_one_throw_with_doubled_masses_and_forces():
    """On the motor, two identical throws whose cranks coincide (0 and 360 deg) put twice one
    throw's inertia and torque on the crank, and each throw's clearance angle obeys an
    equation homogeneous in its masses and forces: the machine equals one throw with every
    mass, inertia and the load doubled. The two runs take their own steps (their rounding
    differs: sin(theta + 2 pi) is not sin(theta) to the bit, and 2 I is summed as I + I), so
    they agree to the integration's tolerance: states to 1e3 rtol of their size over a
    quarter revolution (measured: the clearance rates 1.1e-9, the angles 7e-13, the crank's
    speed 6e-15)."""
    from recipdyn.model.registry import get_model

    two = _model(_two(phases=(0.0, 2 * math.pi), extra=()))
    v2 = two.parameters({f"throw2.{k}": two.parameters()[f"throw1.{k}"]
                         for k in ("rc", "r", "l", "m2", "m3", "J2", "d")})  # fmt: skip
    one = get_model("compressor")
    base = {k: v2[f"throw1.{k}"] for k in ("rc", "r", "l", "d", "g")}
    doubled = {k: 2 * v2[f"throw1.{k}"] for k in ("m1", "m2", "m3", "J1", "J2")}
    v1 = one.parameters({**base, **doubled, "load_amplitude": 2 * v2["throw1.load_amplitude"],
                         "drive": "motor", "omega": v2["shaft.omega"],
                         "J_drive": v2["shaft.J_drive"]})  # fmt: skip
    rtol = 1e-10
    kw = dict(revolutions=0.25, fs=4000.0, rtol=rtol, atol=1e-12)
    a = _simulate(model=two, params=v2, **kw)
    b = _simulate(model=one, params=v1, **kw)
    for name in ("theta_c", "thetadot_c"):
        ref = b[name].values
        for t in ("throw1", "throw2"):
            err = np.max(np.abs(a[f"{t}.{name}"].values - ref)) / np.max(np.abs(ref))
            assert err < 1e3 * rtol, (t, name, err)
    for name in ("omega1", "theta1"):
        err = np.max(np.abs(a[name].values - b[name].values)) / np.max(np.abs(b[name].values))
        assert err < 1e3 * rtol, (name, err)


def test_each_throws_power_and_the_machines_energy_balance():
    """Energy, two different throws on the motor. Per throw at random states of a run: the
    rate of its energy (its crank, rod and crosshead, by a central difference along the
    flow, step 1e-8 of the period: truncation ~(1e-8 T / 1 ms)^2 ~ 1e-10, rounding ~eps E / h
    ~ 1e-11 of the power) equals the power of the torque the
    shaft applies to its crank plus its gas force's, ``torque w + F v3``, to 1e-6 of the
    largest term. Over the run: E(t) - E(0) = W_motor + sum W_gas to the integration's
    tolerance (1e-7 of the motor's work; measured 1.6e-13). And the shaft's equation: the
    throws' torques sum to T_m - J_drive alpha1 at every sample, to rounding (1e-9 of the
    motor torque; measured 1.1e-15)."""
    from recipdyn.model.mechanism.link import mechanism_energy

    model = _model(_two(phases=(0.0, 2.0)))
    v = model.parameters()
    ds = _simulate(model=model, params=v, revolutions=0.5, fs=4000.0)
    total = ds["energy"].values - ds["energy"].values[0]
    work = ds["W_motor"].values + ds["throw1.W_gas"].values + ds["throw2.W_gas"].values
    assert np.max(np.abs(total - work)) < 1e-7 * np.max(np.abs(ds["W_motor"].values))
    torques = ds["throw1.crank_torque"].values + ds["throw2.crank_torque"].values
    shaft = ds["motor_torque"].values - v["shaft.J_drive"] * ds["alpha1"].values
    assert np.max(np.abs(torques - shaft)) < 1e-9 * np.max(np.abs(ds["motor_torque"].values))
    c = model.configuration(v)
    st = c.layout.state
    sys_ = model.system(v)
    h = 1e-8 * 2 * math.pi / v["shaft.omega"]
    for i in (50, 300, 600):
        y = np.array([ds[n].values[i] for n in st.names])
        f = sys_.f(0.0, y)
        for t, local in zip(("throw1", "throw2"), model.throws(v), strict=True):
            p = model.throw_params(local)
            s = st.start(f"{t}.mechanism")

            def energy(yy, p=p, s=s, ph=local["phase"]):
                return mechanism_energy(p, [yy[st["theta1"]] + ph], [yy[s]],
                                        [yy[st["omega1"]]], [yy[s + 1]])[0]  # fmt: skip

            rate = (energy(y + h * f) - energy(y - h * f)) / (2 * h)
            torque = ds[f"{t}.crank_torque"].values[i] * y[st["omega1"]]
            gas = f[st[f"{t}.W_gas"]]
            scale = max(abs(rate), abs(torque), abs(gas))
            assert abs(rate - torque - gas) < 1e-6 * scale, (t, i, rate, torque, gas)


def test_simulate_a_machine_file_from_the_command_line(tmp_path, capsys):
    """``recipdyn simulate --machine examples/machines/two_throw.toml`` runs, records each
    throw's channels under its name and the crank's, and draws each throw by crank angle;
    ``--set throw2.rc=...`` sets one throw's parameter; the compressor's flat name is refused
    with the namespaced ones suggested; a bad machine file is refused in one line."""
    import xarray as xr

    out = tmp_path / "two.nc"
    args = ["simulate", "--machine", str(TWO_THROW), "-n", "0.5", "--fs", "2 kHz",
            "--no-progress", "-o", str(out), "--set", "throw2.rc=0.5 mm"]  # fmt: skip
    assert main(args) == 0
    ds = xr.open_dataset(out)
    assert {"throw1.a", "throw2.a", "throw1.gas_force", "omega1", "theta1"} <= set(ds)
    assert ds.attrs["param_throw2.rc"] == pytest.approx(0.5e-3)
    assert ds.attrs["param_throw1.rc"] == pytest.approx(1e-3)
    assert out.with_suffix(".png").stat().st_size > 20000
    capsys.readouterr()
    assert main([*args[:-2], "--set", "rc=1 mm"]) == 2
    err = capsys.readouterr().err.strip()
    assert "throw1.rc" in err and len(err.splitlines()) == 1 and "Traceback" not in err
    bad = tmp_path / "bad.toml"
    bad.write_text('[[throw]]\ncrank_joint = "contact"\n[[throw]]\n')
    assert main(["simulate", "--machine", str(bad), "-o", str(tmp_path / "b.nc")]) == 2
    err = capsys.readouterr().err.strip()
    assert "throw2.crank_joint = 'link'" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "b.nc").exists()


def test_a_machine_file_is_read_with_its_structure_and_refuses_what_it_cannot_hold(tmp_path):
    """The example file: two throws, their phases and stage, the motor, the sensor that gives
    the vibration signal; the parameters of the shaft and of a stage are refused on a throw,
    an unknown section is refused, each in one line naming it."""
    m = read_machine(TWO_THROW)
    assert [t.name for t in m.throws] == ["throw1", "throw2"]
    assert m.shaft.drive == "motor" and m.sensors[0].signal == "throw2.a"
    model = _model(m)
    assert model.vibration() == ("throw2.a", "m/s**2")
    assert model.parameters()["throw2.phase"] == pytest.approx(math.pi)
    for text, words in (
        ("[[throw]]\nomega = 3\n[[throw]]\n", "throw1.omega: a parameter of [shaft]"),
        ("[frame]\nmass = 1\n[[throw]]\n", "frame: needs at least 2 [[frame.mount]]"),
        ("[gearbox]\nmass = 1\n[[throw]]\n", "unknown key 'gearbox'"),
        ('[[throw]]\nload = "nope"\n[[throw]]\n', "load = 'nope'"),
    ):
        f = tmp_path / "m.toml"
        f.write_text(text)
        with pytest.raises(ParameterError) as exc:
            read_machine(f)
        assert words in str(exc.value) and "\n" not in str(exc.value), str(exc.value)


@pytest.mark.parametrize("case", ["value", "structure"])
def test_a_bad_machine_is_refused_before_the_compiled_code_loads(tmp_path, case):
    """A machine file's bad value (``--set throw2.rc=-1mm``) or bad structure is answered in
    one line with exit status 2 before numba, xarray, SciPy or the kernels load (a fresh
    interpreter: the model of a machine is built and validated without compiled code)."""
    from test_cli_refusals import _fresh

    f = tmp_path / "bad.toml"
    f.write_text('[[throw]]\nload = "cycle"\n[[throw]]\nload = "paper"\n')
    args = (["simulate", "--machine", str(TWO_THROW), "--set", "throw2.rc=-1 mm"]
            if case == "value" else ["simulate", "--machine", str(f)])  # fmt: skip
    res = _fresh([*args, "-o", "o/x.nc"], tmp_path)
    assert res["code"] == 2, res["err"]
    assert res["heavy"] == [], res["heavy"]
    assert len(res["err"].strip().splitlines()) == 1, res["err"]
    assert ("throw2.rc" if case == "value" else "one kind of load") in res["err"]


def test_a_throws_derived_defaults_follow_its_own_values():
    """The compressor's derived defaults (``ls = l / 2``, ``J2 = m2 l**2 / 12``) hold per
    throw: ``throw2.ls`` follows ``throw2.l``, not ``throw1.l``; a value the machine file
    gives is kept (the file's, not the rule's)."""
    from recipdyn.model.protocol import Derived

    m = _model(_two())
    v = m.parameters({"throw2.l": 0.5, "throw1.l": 0.7})
    assert v["throw2.ls"] == pytest.approx(0.25) and isinstance(v["throw2.ls"], Derived)
    assert v["throw1.ls"] == pytest.approx(0.35)
    assert v["throw1.J2"] == pytest.approx(v["throw1.m2"] * 0.7**2 / 12)
    assert v["throw2.J2"] == 0.7  # (the file's value: _two gives it)
    f = Machine("m", throws=(Throw("throw1", params=(("ls", 0.2),)), Throw("throw2")))
    w = _model(f).parameters()
    assert w["throw1.ls"] == 0.2 and w["throw2.ls"] == pytest.approx(w["throw2.l"] / 2)
