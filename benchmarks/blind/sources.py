"""Where the blind set's records come from, and the set itself.

A record is physics (`Physics`: what made the signals) seen through a chain (`RecordSpec`:
this package's independent chain, `blind.chain`, or recipdyn's own `recipdyn.sensors` for
the controls and the issue's examples), with the channels a user would give the diagnoser.
Four sources of physics:

* ``recipdyn``: recipdyn's ``compressor-contact-valves`` at operating points drawn inside the
  data set's ranges (`recipdyn.diagnosis.classes.CONDITIONS`), each class of
  `recipdyn.diagnosis.classes.CLASSES` set as the class says (its parameter at a drawn
  severity, the settings it requires), from the healthy `BASELINE`;
* ``machine``: the same model for another machine (rod or stroke +-30 %, masses x1.5, 6 bar
  discharge, a user's 180 mm stroke / 450 mm rod / 300 mm bore machine at 200 and 1000 rpm);
* ``other-model``: the second model of `blind.other_model` (its own equations, contact
  damping, quasi-static valves and integrator);
* ``negative``: signals of no compressor (noise, a gearbox, a rolling bearing, a pump).

Everything is drawn from one seed (`blind_set`). Nothing here writes a data set: the records
live in memory, their physics optionally in a cache of ``.npz`` files that only this harness
reads, so the blind set never enters a training set (`recipdyn dataset` builds its own
records from its own seed).
"""

from __future__ import annotations

import hashlib
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import chain as C

__all__ = ["Physics", "RecordSpec", "physics", "blind_set", "conditions", "recipdyn_physics"]


@dataclass(frozen=True)
class Physics:
    """What made a record's signals. ``params``: sorted (name, value) pairs."""

    source: str  # "recipdyn", "machine", "other-model", "negative"
    params: tuple
    truth: str | None  # class name (None: no compressor)
    severity: float | None  # the class's severity of the fault parameter's value
    revolutions: float = 4.0
    transient: float = 1.0
    note: str = ""
    fs: float = C.FS_PHYS  # sampling rate of the physics (recipdyn's own chain samples at it)

    @property
    def key(self) -> str:
        text = repr((self.source, self.params, self.revolutions, self.transient))
        if self.fs != C.FS_PHYS:
            text += repr(self.fs)
        return hashlib.sha1(text.encode()).hexdigest()[:16]

    def p(self) -> dict:
        return dict(self.params)


@dataclass(frozen=True)
class RecordSpec:
    """One record of the blind set."""

    id: str
    family: str
    physics: Physics
    chain: C.Chain | None = None  # None: recipdyn's own chain with ``own`` settings
    own: tuple = ()  # (name, value) pairs for recipdyn.sensors (resonance_hz, snr_db)
    fs: float = C.FS_PHYS / 6  # acquisition rate of recipdyn's own chain
    channels: str = "all"  # "all", "accel+tacho", "accel+speed"
    seed: int = 0
    expect: str = "class"  # "class": the true class or a refusal; "refuse"
    edits: tuple = ()  # applied to the channels after the chain (blind.edits)
    note: str = ""
    group: str = ""  # target group (blind.harness.TARGETS)


# ------------------------------------------------------------------------------ physics


def recipdyn_physics(params: dict, revolutions: float, transient: float, fs: float) -> dict:
    """recipdyn's ``compressor-contact-valves`` (the diagnoser's model) at ``params``."""
    from recipdyn.diagnosis.classes import MODEL
    from recipdyn.simulate import simulate

    with warnings.catch_warnings():  # the healthy pins stretch Hertz's law (docs/diagnosis.md)
        warnings.simplefilter("ignore")
        ds = simulate(model=MODEL, revolutions=revolutions, transient=transient, fs=fs,
                      summary=False, columns=["a", "theta1", "p_head", "p_crank"],
                      **params)  # fmt: skip
    out = {k: np.asarray(ds[k].values, float) for k in ("a", "theta1", "p_head", "p_crank")}
    out["t"] = np.asarray(ds["time"].values, float)
    out["fs"] = fs
    return out


def _negative(p: dict, revolutions: float, fs: float) -> dict:
    """Signals of no compressor, with a tacho turning at ``rpm`` (inside the training speed
    range, so that a refusal has to come from the signals themselves)."""
    rng = np.random.default_rng(int(p["seed"]))
    f_rev = p["rpm"] / 60
    n = int(round(revolutions / f_rev * fs))
    t = np.arange(n) / fs
    theta = 2 * math.pi * f_rev * t
    kind = p["kind"]
    ph = np.full(n, 1.0e5) + rng.standard_normal(n) * 50
    pc = np.full(n, 1.0e5) + rng.standard_normal(n) * 50
    if kind == "white":
        a = rng.standard_normal(n) * 50.0
    elif kind == "gearbox":  # a 37-tooth pinion on a shaft at 4.3x the tacho's, sidebands
        f_s = 4.3 * f_rev
        a = np.zeros(n)
        for h in (1, 2, 3):
            mod = 1 + 0.3 * np.cos(2 * math.pi * f_s * t)
            a += 40 / h * mod * np.sin(2 * math.pi * h * 37 * f_s * t + h)
        a += rng.standard_normal(n) * 5
    elif kind == "bearing":  # outer-race defect: impacts at 5.43x the shaft ringing at 3.6 kHz
        from scipy import signal

        bpfo = 5.43 * f_rev
        imp = np.zeros(n)
        for tk in np.arange(0.0, t[-1], 1 / bpfo):
            i = int(tk * fs + rng.normal(0, 0.001 * fs / bpfo))
            if 0 <= i < n:
                imp[i] = 1.0
        w = 2 * math.pi * 3600.0
        b, aa = signal.bilinear([w * w], [1, 2 * 0.05 * w, w * w], fs)
        a = signal.lfilter(b, aa, imp) * 2000 + rng.standard_normal(n) * 3
    elif kind == "pump":  # a 7-vane centrifugal pump: vane pass in the pressures and vibration
        vp = 7 * f_rev * 5  # the pump turns at 5x the tacho's shaft
        a = 30 * np.sin(2 * math.pi * vp * t) + 10 * np.sin(4 * math.pi * vp * t)
        a += rng.standard_normal(n) * 8
        ph = 3e5 + 2e4 * np.sin(2 * math.pi * vp * t) + rng.standard_normal(n) * 100
        pc = 1e5 + 5e3 * np.sin(2 * math.pi * vp * t + 1) + rng.standard_normal(n) * 100
    else:
        raise ValueError(f"negative kind {kind!r}")
    return {"t": t, "theta1": theta, "a": a, "p_head": ph, "p_crank": pc, "fs": fs}


def _compute(spec: Physics) -> dict:
    p = spec.p()
    if spec.source in ("recipdyn", "machine"):
        return recipdyn_physics(p, spec.revolutions, spec.transient, spec.fs)
    if spec.source == "other-model":
        from .other_model import Machine, simulate_other

        return simulate_other(Machine(**p), revolutions=spec.revolutions,
                              transient=spec.transient, fs=C.FS_PHYS)  # fmt: skip
    if spec.source == "negative":
        return _negative(p, spec.revolutions, spec.fs)
    raise ValueError(f"source {spec.source!r}")


def physics(spec: Physics, cache: Path | None = None) -> dict:
    """The physics record of ``spec`` (from ``cache`` if it holds it)."""
    import recipdyn

    if cache is not None:
        path = Path(cache) / f"{spec.source}-{spec.key}-{recipdyn.__version__}.npz"
        if path.exists():
            with np.load(path) as z:
                out = {k: z[k] for k in z.files}
            out["fs"] = float(out["fs"])
            return out
    out = _compute(spec)
    if cache is not None:
        Path(cache).mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".tmp.npz")
        np.savez_compressed(tmp, **{k: np.asarray(v) for k, v in out.items() if k != "params"})
        tmp.replace(path)
    return out


# ---------------------------------------------------------------------------- the set


def conditions(rng, n: int) -> list[dict]:
    """Operating points drawn uniformly in the data set's ranges (and an acquisition rate and
    a mounting resonance, an SNR for recipdyn's own chain, drawn like the data set's)."""
    from recipdyn.diagnosis.classes import CONDITIONS

    out = []
    for _ in range(n):
        c = {k: CONDITIONS[k].draw(rng) for k in
             ("omega", "suction_pressure", "discharge_pressure", "m2", "m3")}  # fmt: skip
        c["_resonance_hz"] = CONDITIONS["resonance_hz"].draw(rng)
        c["_snr_db"] = float(rng.uniform(10.0, 40.0))
        c["_k"] = int(rng.choice([5, 6]))
        out.append(c)
    return out


def _items(d: dict) -> tuple:
    return tuple(sorted((k, v) for k, v in d.items() if not k.startswith("_")))


def class_physics(cond: dict, name: str, severity: float, *, extra: dict | None = None,
                  revolutions: float = 4.0, source: str = "recipdyn", note: str = "",
                  fs: float = C.FS_PHYS) -> Physics:  # fmt: skip
    """recipdyn's model at ``cond`` with class ``name`` at ``severity`` (and ``extra``
    parameters: another machine)."""
    from recipdyn.diagnosis.classes import BASELINE, get_class

    fc = get_class(name)
    p = dict(BASELINE)
    p.update({k: v for k, v in cond.items() if not k.startswith("_")})
    p.update(fc.overrides(severity))
    p.update(extra or {})
    return Physics(source, _items(p), name, severity if fc.parameter else None,
                   revolutions=revolutions, note=note, fs=fs)  # fmt: skip


def own(cond: dict) -> tuple:
    return (("resonance_hz", cond["_resonance_hz"]), ("snr_db", cond["_snr_db"]))


#: Other machines (recipdyn's physics), as parameter changes from the nominal machine.
MACHINES: dict[str, dict] = {
    "rod +30 %": {"l": 0.78, "ls": 0.39, "J2": 0.6 * 1.3**2},
    "rod -30 %": {"l": 0.42, "ls": 0.21, "J2": 0.6 * 0.7**2},
    "stroke +30 %": {"r": 0.156, "rs": 0.078},
    "stroke -30 %": {"r": 0.084, "rs": 0.042},
    "masses x1.5": {"m2": 30.0, "m3": 45.0, "J2": 0.9},
    "6 bar discharge": {"discharge_pressure": 6e5},
    "own machine, 200 rpm": {
        "r": 0.09,
        "rs": 0.045,
        "l": 0.45,
        "ls": 0.225,
        "bore": 0.3,
        "omega": 200 * 2 * math.pi / 60,
    },  # fmt: skip
    "own machine, 1000 rpm": {
        "r": 0.09,
        "rs": 0.045,
        "l": 0.45,
        "ls": 0.225,
        "bore": 0.3,
        "omega": 1000 * 2 * math.pi / 60,
    },  # fmt: skip
}

#: The nominal operating point (the paper's): what a machine variant is run at.
NOMINAL = {"omega": 20.0, "suction_pressure": 1e5, "discharge_pressure": 3e5, "m2": 20.0,
           "m3": 30.0, "_resonance_hz": 3750.0, "_snr_db": 25.0, "_k": 6}  # fmt: skip


def one_effect_chains(rng) -> dict[str, C.Chain]:
    """`chain.NEUTRAL` with one effect changed, its value drawn in its range (`chain.RANGES`)."""
    N, d = C.NEUTRAL, lambda k: C.RANGES[k].draw(rng)
    p = {}

    def both(**kw):
        return {"p_head": kw, "p_crank": kw}

    p["accel gain error"] = C.with_(N, accel={"gain_error": d("accel.gain_error")})
    p["accel resonance 2.5-7 kHz"] = C.with_(N, accel={"resonance_hz": d("accel.resonance_hz")})
    p["accel damping 0.03-0.15"] = C.with_(N, accel={"damping": d("accel.damping")})
    p["accel mount transmissibility"] = C.with_(N, accel={"mount": "transmissibility"})
    p["accel IEPE high-pass 0.1-1 Hz 1st order"] = C.with_(
        N, accel={"highpass_hz": d("accel.highpass_hz"), "highpass_order": 1}
    )
    p["accel structural background"] = C.with_(
        N, accel={"background_snr_db": d("accel.background_snr_db")}
    )
    p["accel analogue noise"] = C.with_(
        N, accel={"noise_snr_db": d("accel.noise_snr_db"), "adc_noise_snr_db": None}
    )
    p["accel mains hum"] = C.with_(N, accel={"hum_amplitude": d("accel.hum_amplitude"),
                                             "hum_hz": d("accel.hum_hz")})  # fmt: skip
    p["accel baseline wander"] = C.with_(N, accel={"wander_amplitude": d("accel.wander_amplitude")})
    p["accel full scale 250 g"] = C.with_(N, accel={"full_scale": 250 * C.G})
    p["pressure passage resonance"] = C.with_(
        N, **both(passage_hz=d("p.passage_hz"), passage_damping=d("p.passage_damping"))
    )
    p["pressure gain error"] = C.with_(N, p_head={"gain_error": d("p.gain_error")},
                                       p_crank={"gain_error": d("p.gain_error")})  # fmt: skip
    p["pressure offsets"] = C.with_(N, p_head={"offset_pa": d("p.offset_pa")},
                                    p_crank={"offset_pa": d("p.offset_pa")})  # fmt: skip
    p["pressure thermal drift"] = C.with_(N, p_head={"drift_pa": d("p.drift_pa")},
                                          p_crank={"drift_pa": d("p.drift_pa")})  # fmt: skip
    p["pressure causal low-pass"] = C.with_(
        N,
        **both(
            lowpass_hz=d("p.lowpass_hz"),
            lowpass_order=d("p.lowpass_order"),
            lowpass_kind=d("p.lowpass_kind"),
        ),  # fmt: skip
    )
    p["pressure noise 50-300 Pa"] = C.with_(N, **both(noise_pa=d("p.noise_pa")))
    p["pressure skew"] = C.with_(N, **both(delay_s=d("p.delay_s")))
    p["tacho mark +-1 deg"] = C.with_(N, tacho={"mark_deg": d("tacho.mark_deg")})
    p["tacho width 2-30 deg"] = C.with_(N, tacho={"width_deg": d("tacho.width_deg")})
    p["tacho negative pulse on -10..0 V"] = C.with_(
        N, tacho={"polarity": -1, "baseline_v": d("tacho.baseline_v"), "full_scale_v": 20.0}
    )
    p["tacho rise time"] = C.with_(N, tacho={"rise_s": d("tacho.rise_s")})
    p["tacho jitter 0-0.5 deg"] = C.with_(N, tacho={"jitter_deg": d("tacho.jitter_deg")})
    p["tacho noise 0-0.05 V"] = C.with_(N, tacho={"noise_v": d("tacho.noise_v")})
    p["card delta-sigma FIR"] = C.with_(N, acq={"antialias": "delta-sigma"})
    p["card elliptic anti-alias"] = C.with_(
        N, acq={"antialias": "elliptic", "order": d("acq.order"), "corner": d("acq.corner")}
    )
    p["card Bessel anti-alias"] = C.with_(
        N, acq={"antialias": "bessel", "order": d("acq.order"), "corner": d("acq.corner")}
    )
    p["card 12 288 Hz"] = C.with_(N, acq={"fs": C.FS_PHYS / 5})
    p["card 24 bit"] = C.with_(N, acq={"bits": 24})
    return p


def installation_errors(rng) -> dict[str, tuple[C.Chain, tuple]]:
    """Chains outside `chain.RANGES`: mistakes of an installation (the answer should be
    right or a refusal, never a confident wrong class)."""
    from . import edits as E

    N = C.NEUTRAL
    return {
        "hand-held probe (1.2 kHz)": (
            C.with_(N, accel={"resonance_hz": 1200.0, "damping": 0.1}),
            (),
        ),  # fmt: skip
        "accel range 50 g (clips)": (C.with_(N, accel={"full_scale": 50 * C.G}), ()),
        "tacho on a digital input, card delay not compensated": (
            C.with_(N, acq={"antialias": "delta-sigma"}, tacho={"through_adc": False}),
            (),
        ),
        "gauge pressure transducers": (
            C.with_(N, p_head={"offset_pa": -101325.0}, p_crank={"offset_pa": -101325.0}),
            (),
        ),  # fmt: skip
        "head and crank pressures swapped": (N, (E.SwapPressures(),)),
        "tacho mark 5 deg late": (C.with_(N, tacho={"mark_deg": 5.0}), ()),
        "pressures 2 ms late": (
            C.with_(N, p_head={"delay_s": 2e-3}, p_crank={"delay_s": 2e-3}),
            (),
        ),  # fmt: skip
    }


#: The tacho's pulse settings (the neutral values keep the data set's pulse).
TACHO_PULSE = ("mark_deg", "width_deg", "polarity", "baseline_v", "amplitude_v", "rise_s",
               "jitter_deg", "noise_v")  # fmt: skip


def blind_set(seed: int = 20240, *, quick: bool = False, severity_range=(0.5, 1.0)) -> list:
    """The blind set's records (`RecordSpec`), all drawn from ``seed``. ``quick``: one
    operating condition and a reduced set of each family (the benchmark's quick mode)."""
    from recipdyn.diagnosis.classes import CLASSES, get_class

    rng = np.random.default_rng(seed)
    n_cond = 1 if quick else 4
    conds = conditions(rng, n_cond)
    names = [c.name for c in CLASSES]
    recs: list[RecordSpec] = []
    seeds = iter(rng.integers(0, 2**31, 100_000))
    phys: list[tuple[dict, Physics]] = []
    for cond in conds:
        for name in names:
            s = float(rng.uniform(*severity_range))
            phys.append((cond, class_physics(cond, name, s)))

    def add(family, ph, group, **kw):
        i = sum(r.family == family for r in recs)
        recs.append(RecordSpec(id=f"{family} #{i}", family=family, physics=ph, group=group,
                               seed=int(next(seeds)), **kw))  # fmt: skip

    # A: recipdyn's physics, inside the training ranges
    for cond, ph in phys:
        add("A0 control: recipdyn's own chain", ph, "control", own=own(cond),
            fs=C.FS_PHYS / cond["_k"])  # fmt: skip
        add("A1 control: neutral chain", ph, "control",
            chain=C.with_(C.NEUTRAL, acq={"fs": C.FS_PHYS / cond["_k"]}))  # fmt: skip
    n_cls = len(names)

    def pick(j, i, per):
        """The i-th of ``per`` physics records for effect j: every class once over 9 (a
        third of them, shifted by j, over 3), the conditions in turn."""
        cls = (i * (n_cls // per) + j) % n_cls if per < n_cls else i % n_cls
        return phys[((j + i) % n_cond) * n_cls + cls]

    per_effect = 3 if quick else 9
    for j, name in enumerate(one_effect_chains(rng)):
        for i in range(per_effect):
            _, ph = pick(j, i, per_effect)
            ch = one_effect_chains(rng)[name]  # a new draw of the effect's value
            add(f"A2 one effect: {name}", ph, "chain", chain=ch)
    n_all = 1 if quick else 3
    for _, ph in phys:
        for _ in range(n_all):
            add("A3 all effects drawn", ph, "chain", chain=C.draw_chain(rng))
        ch = C.draw_chain(rng)  # all effects but the tacho's: what the rest does to an answer
        ch = C.with_(ch, tacho={f: getattr(C.NEUTRAL.tacho, f) for f in TACHO_PULSE})
        add("A3t all effects drawn but the tacho's", ph, "chain", chain=ch)
        add("A4 all effects drawn, accel + tacho", ph, "chain-reduced",
            chain=C.draw_chain(rng), channels="accel+tacho")  # fmt: skip
        add("A5 all effects drawn, accel + speed", ph, "chain-reduced",
            chain=C.draw_chain(rng), channels="accel+speed")  # fmt: skip
    for j, (name, (ch, ed)) in enumerate(installation_errors(rng).items()):
        per = 3 if quick else 9
        for i in range(per):
            _, ph = pick(j, i, per)
            add(f"A6 installation error: {name}", ph, "installation", chain=ch, edits=ed)
    # B: other machines, recipdyn's physics
    machines = list(MACHINES.items())
    if quick:
        machines = [m for m in machines if m[0] in ("rod +30 %", "own machine, 200 rpm")]
    for mname, extra in machines:
        for name, s in (("healthy", 0.0), ("crank_pin_clearance", None),
                        ("suction_valve_leak", 0.75)):  # fmt: skip
            if quick and name == "suction_valve_leak":
                continue
            if s is None:  # a 0.5 mm crank pin
                s = get_class(name).severity(5e-4)
            ph = class_physics(NOMINAL, name, s, extra=extra, source="machine", note=mname)
            add(f"B other machine: {mname}", ph, "machine", own=own(NOMINAL), expect="refuse")
            add(f"B other machine: {mname}", ph, "machine", chain=C.NEUTRAL, expect="refuse")
    # C: another model's physics
    other = [("healthy", {"clearance": 1e-4}), ("crank_pin_clearance", {"clearance": 3e-4}),
             ("crank_pin_clearance", {"clearance": 5e-4}),
             ("crank_pin_clearance", {"clearance": 8e-4}),
             ("suction_valve_leak", {"leak_suction_head": 1.5e-4}),
             ("discharge_valve_leak", {"leak_discharge_head": 2.5e-5}),
             ("ring_leak", {"ring_leak": 1e-4})]  # fmt: skip
    if quick:
        other = other[:2]
    for name, p in other:
        fc = get_class(name)
        val = next(iter(p.values()))
        sev = fc.severity(val) if fc.parameter else None
        if name == "healthy":
            p = dict(p)
        ph = Physics("other-model", _items(p), name, sev, revolutions=4.0, transient=2.0)
        add("C another model", ph, "other-model", chain=C.NEUTRAL)
        add("C another model, accel + tacho", ph, "other-model", chain=C.NEUTRAL,
            channels="accel+tacho")  # fmt: skip
    # D: no compressor
    kinds = ("white", "gearbox", "bearing", "pump")
    for kind in kinds[:2] if quick else kinds:
        ph = Physics("negative", _items({"kind": kind, "rpm": 190.0, "seed": 7}), None, None)
        add("D not a compressor", ph, "negative", chain=C.NEUTRAL, expect="refuse")
        add("D not a compressor, accel + tacho", ph, "negative", chain=C.NEUTRAL,
            channels="accel+tacho", expect="refuse")  # fmt: skip
    return recs
