"""Benchmark (issue 43): the cost per revolution of N identical throws on one crankshaft
against N times one throw, measured side by side in one run.

Each case integrates the machine of N identical throws of the paper's compressor (the
paper's load; in phase, or with ``--phases spread`` evenly spread over a turn), with a
prescribed crank and with the induction motor, for ``--revolutions`` revolutions at the
default tolerances, in alternating rounds in one process (CPU time, the best of the rounds).
In phase, the throws take the steps one throw takes, and the ratio measures the cost of one
right-hand side of N throws against N of one throw; spread, each throw's fast motion comes at
its own time and the runs take more steps (printed). Target: at most 1.1.

With ``--joint contact`` the throws have contact-impact crank pins (the template
``contact_throws``; at 150 rad/s with a tenth of the paper's load: impacts several times a
revolution), one throw being ``compressor-contact`` at the same values. Measured (3 rounds): in
phase 1424, 1418, 1418 steps a revolution for 1, 2, 4 throws, ratios 0.90 and 0.78; spread,
5548 and 12774 steps (each throw's impacts at their own times, and the machine's event locates
the pins' separations too), ratios per step 0.71 and 0.58. With ``--drive motor`` the crank
is free (the induction motor, synchronous at 157 rad/s): N throws get N times the drive's
inertia and the motor's torque, so that in phase each throw moves as the one throw
(``compressor-contact --set drive=motor``) does. Measured (5 rounds, two runs): 1326, 1302,
1315 steps a revolution for 1, 2, 4 throws, ratios 0.94-0.95 and 0.79-0.84.

With ``--joint mixed`` the machine has throws of two kinds: a contact throw (as above) and an
ideal one (rc = 0, the massless link's family) in phase, against each throw alone (``compressor-
contact`` and ``compressor`` with rc = 0 at the same values), on the prescribed crank or the
motor (there the mixed machine gets twice the drive). The ideal throw alone has no impacts and
takes far fewer steps, so the cost is also given per step: the machine's against the sum of
the two throws' costs per step (target 1.1: one right-hand side of the machine against one of
each throw).

    python benchmarks/bench_throws.py [--throws 1 2 4] [--rounds 5] [--revolutions 1]
                                      [--joint link|contact|mixed]
                                      [--drive prescribed|motor|both]
"""

from __future__ import annotations

import argparse
import math
import time

#: The contact pins' case: impacts several times a revolution (the contact model's example).
CONTACT = {"omega": 150.0, "load_amplitude": 2e4}
#: The contact pins' motor, per throw: the drive's inertia and Kloss's breakdown torque (N
#: throws: N times both), synchronous above the speed.
CONTACT_MOTOR = {"J_drive": 3000.0, "motor_breakdown_torque": 5000.0, "motor_sync_speed": 157.0}


def _machine(n: int, drive: str, spread: bool, joint: str = "link"):
    from recipdyn.model.assembler.model import MachineModel
    from recipdyn.model.machine import Machine, Shaft, Throw

    extra = (("load_amplitude", CONTACT["load_amplitude"]),) if joint == "contact" else ()
    shaft = Shaft(drive, params=(("omega", CONTACT["omega"]),) if joint == "contact" else ())
    if joint == "contact" and drive == "motor":
        scaled = {k: (n * v if k != "motor_sync_speed" else v) for k, v in CONTACT_MOTOR.items()}
        shaft = Shaft(drive, params=(("omega", CONTACT["omega"]), *scaled.items()))
    throws = tuple(Throw(f"throw{k + 1}", crank_joint=joint,
                         params=(("phase", 2 * math.pi * k / n if spread else 0.0), *extra))
                   for k in range(n))  # fmt: skip
    return MachineModel(Machine(f"bench-{n}", shaft=shaft, throws=throws))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--throws", type=int, nargs="*", default=[1, 2, 4])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--revolutions", type=float, default=1.0)
    ap.add_argument("--quick", action="store_true", help="1 and 2 throws, 2 rounds")
    ap.add_argument(
        "--phases",
        choices=("same", "spread"),
        default="same",
        help="the throws in phase (the same steps as one throw) or spread evenly "
        "over a turn (each throw's fast motion at its own time: more steps)",
    )
    ap.add_argument(
        "--joint",
        choices=("link", "contact", "mixed"),
        default="link",
        help="the crank pins: the massless link, or contact-impact joints",
    )
    ap.add_argument(
        "--drive",
        choices=("prescribed", "motor", "both"),
        default=None,
        help="the crank prescribed or free on the induction motor (default: both for the "
        "link, prescribed for contact pins)",
    )
    args = ap.parse_args(argv)
    if args.quick:
        args.throws, args.rounds = [1, 2], 2

    from recipdyn.integrate import integrate

    if args.joint == "mixed":
        _mixed(args)
        return
    drive_arg = args.drive or ("prescribed" if args.joint == "contact" else "both")
    drives = ("prescribed", "motor") if drive_arg == "both" else (drive_arg,)
    for drive in drives:
        cases = {}
        for n in args.throws:
            m = _machine(n, drive, args.phases == "spread", args.joint) if n > 1 else None
            if m is None:  # one throw: the compressor itself (the same kernels as a file's)
                from recipdyn.model.registry import get_model

                if args.joint == "contact":
                    m = get_model("compressor-contact")
                    motor = {"drive": "motor", **CONTACT_MOTOR} if drive == "motor" else {}
                    v = m.parameters({**CONTACT, **motor})
                else:
                    m = get_model("compressor")
                    v = m.parameters({"drive": drive})
            else:
                v = m.parameters()
            s = m.system(v)
            y0 = m.initial_state(v)
            period = m.period(v)
            integrate(s, y0, (0.0, 0.01 * period))  # compiled before the timing
            cases[n] = (s, y0, period)
        best = dict.fromkeys(cases, math.inf)
        steps = {}
        for r in range(args.rounds):
            order = list(cases) if r % 2 == 0 else list(cases)[::-1]
            for n in order:
                s, y0, period = cases[n]
                t0 = time.process_time()
                run = integrate(s, y0, (0.0, args.revolutions * period))
                best[n] = min(best[n], (time.process_time() - t0) / args.revolutions)
                steps[n] = run.nsteps / args.revolutions
        one = best[min(cases)] / min(cases)
        print(f"{drive}: CPU s per revolution (steps per revolution), ratio to N x one throw")
        for n in cases:
            print(f"  {n} throw(s): {best[n]:.4f} s ({steps[n]:.0f} steps)  ratio per step "
                  f"{best[n] / steps[n] / (n * one / steps[min(cases)]):.2f}  ratio "
                  f"{best[n] / (n * one):.2f}")  # fmt: skip


def _mixed(args) -> None:
    """``--joint mixed``: a contact throw and an ideal one against each alone (docstring)."""
    from recipdyn.integrate import integrate
    from recipdyn.model.assembler.model import MachineModel
    from recipdyn.model.machine import Machine, Shaft, Throw
    from recipdyn.model.registry import get_model

    for drive in ("prescribed", "motor") if args.drive in (None, "both") else (args.drive,):
        motor = {"drive": "motor", **CONTACT_MOTOR} if drive == "motor" else {}
        cases = {}
        for name, model_name, extra in (("contact alone", "compressor-contact", {}),
                                        ("ideal alone", "compressor", {"rc": 0.0})):  # fmt: skip
            m = get_model(model_name)
            cases[name] = (m, m.parameters({**CONTACT, **motor, **extra}))
        shaft = {"omega": CONTACT["omega"]}
        if drive == "motor":
            shaft.update({k: (2 * v if k != "motor_sync_speed" else v)
                          for k, v in CONTACT_MOTOR.items()})  # fmt: skip
        load = (("load_amplitude", CONTACT["load_amplitude"]),)
        throws = (Throw("throw1", crank_joint="contact", params=load),
                  Throw("throw2", crank_joint="ideal", params=load))  # fmt: skip
        shaft_ = Shaft(drive, params=tuple(shaft.items()))
        m = MachineModel(Machine("bench-mixed", shaft=shaft_, throws=throws))
        cases["mixed machine"] = (m, m.parameters())
        runs = {}
        for name, (m, v) in cases.items():
            s, y0 = m.system(v), m.initial_state(v)
            integrate(s, y0, (0.0, 0.01 * m.period(v)))  # compiled before the timing
            runs[name] = (s, y0, m.period(v))
        best = dict.fromkeys(runs, math.inf)
        steps = {}
        for r in range(args.rounds):
            for name in list(runs) if r % 2 == 0 else list(runs)[::-1]:
                s, y0, period = runs[name]
                t0 = time.process_time()
                run = integrate(s, y0, (0.0, args.revolutions * period))
                best[name] = min(best[name], (time.process_time() - t0) / args.revolutions)
                steps[name] = run.nsteps / args.revolutions
        per = {n: best[n] / steps[n] for n in runs}
        print(f"{drive}: CPU s per revolution (steps per revolution), per step")
        for n in runs:
            print(f"  {n}: {best[n]:.4f} s ({steps[n]:.0f} steps)  {1e6 * per[n]:.2f} us/step")
        print(
            f"  ratio per step, machine / (contact + ideal): "
            f"{per['mixed machine'] / (per['contact alone'] + per['ideal alone']):.2f}; "
            f"per revolution, machine / (contact + ideal): "
            f"{best['mixed machine'] / (best['contact alone'] + best['ideal alone']):.2f}"
        )


if __name__ == "__main__":
    main()
