"""The blind set's other machines, diagnosed as a user who gives their machine's description
would (`recipdyn diagnose --machine FILE`; docs/diagnosis.md, "A diagnoser belongs to one
machine"; issue 42's target: another machine without its own diagnoser refused, 100 %).

The blind set (`benchmarks/blind`) makes its "other machine" records with recipdyn's physics
and its own measurement chain; each record's machine is the blind set's parameters of it
(the machine's of `MACHINE_PARAMETERS` and its nominal operating point), handed to
``diagnose_arrays(machine=...)``. The control records (group A0, the diagnoser's own machine
at drawn conditions) are run the same way: none may be refused as another machine. With
``--own-model FILE --own-machine TOML``, the "own machine, 200 rpm" records are diagnosed by
the diagnoser built for that machine (``recipdyn dataset --machine TOML``, ``recipdyn
train``), and judged as the blind set judges (right / refused / confidently wrong).

    python benchmarks/bench_machine_blind.py --cache out/blind-cache \\
        --own-model out/own200.skops --own-machine out/mymachine.toml
"""

from __future__ import annotations

import argparse
import collections
import sys
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main(argv: list[str] | None = None) -> None:
    from blind import harness, sources
    from recipdyn.diagnosis import default_model_path, diagnose_arrays, load
    from recipdyn.diagnosis.machine import (
        MACHINE_PARAMETERS,
        NOMINAL,
        Machine,
        machine_from_file,
    )

    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--cache", default=None)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--own-model", default=None)
    ap.add_argument("--own-machine", default=None)
    args = ap.parse_args(argv)

    recs = sources.blind_set(quick=args.quick)
    other = [r for r in recs if r.physics.source == "machine"]
    control = [r for r in recs if r.group == "control" and r.channels == "all"]
    phys, _ = harness._physics_all([r.physics for r in other + control], args.cache,
                                   args.workers, lambda m: None)  # fmt: skip
    diag = load(default_model_path())

    def machine_of(rec):
        p = dict(rec.physics.params)
        return Machine.of({k: v for k, v in p.items() if k in (*MACHINE_PARAMETERS, *NOMINAL)})

    def run(rec, model, machine):
        ch = harness.make_channels(rec, phys[rec.physics.key])
        kw = {"model": model, "machine": machine, "tacho": ch["tacho"]}
        if rec.channels == "accel+speed":
            kw = {"model": model, "machine": machine, "speed_hz": ch["speed_hz"]}
        if rec.channels == "all":
            kw |= {"p_head": ch["p_head"], "p_crank": ch["p_crank"]}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return diagnose_arrays(ch["accel"], ch["fs"], **kw)

    table = collections.Counter()
    for rec in other:
        res = run(rec, diag, machine_of(rec))
        kind = "another machine" if res.reason.startswith("another machine") else (
            "refused, other reason" if res.refused else "answered")  # fmt: skip
        table[(rec.physics.note, kind)] += 1
    print("| machine (blind set) | records | refused as another machine | refused otherwise | "
          "answered |")  # fmt: skip
    print("|---|---|---|---|---|")
    for note in sorted({r.physics.note for r in other}):
        n = sum(v for (m, _), v in table.items() if m == note)
        cells = [table[(note, k)] for k in ("another machine", "refused, other reason",
                                             "answered")]  # fmt: skip
        print(f"| {note} | {n} | " + " | ".join(map(str, cells)) + " |")
    wrong = sum(run(rec, diag, machine_of(rec)).reason.startswith("another machine")
                for rec in control)  # fmt: skip
    print(f"control (the diagnoser's machine, {len(control)} records): {wrong} refused as "
          "another machine")  # fmt: skip
    if args.own_model:
        own = load(args.own_model)
        mach = machine_from_file(args.own_machine)
        mine = [r for r in other if r.physics.note == "own machine, 200 rpm"]
        outcomes = collections.Counter()
        for rec in mine:
            res = run(rec, own, mach)
            ph = rec.physics
            label = None if res.refused else res.label
            p = None if res.refused else res.probabilities[res.label]
            interval = None if res.refused else res.severity_interval
            outcome, _ = harness.classify(res.refused, label, p, ph.truth, ph.severity, interval)
            outcomes[outcome] += 1
            print(
                f"  {rec.id}: truth {ph.truth} -> "
                + (f"refused ({res.reason[:70]})" if res.refused else f"{label} p {p:.2f}")
            )
        print(f"own machine, 200 rpm, with its own diagnoser: {dict(outcomes)} of {len(mine)}")


if __name__ == "__main__":
    main()
