"""Benchmark: how to compose compiled components (issue 43, phase 0), measured before designing.

Three questions about numba (the version pinned in requirements/constraints.txt), each
answered in fresh processes that share one empty numba cache folder of their own:

(a) A small glue function that calls separately compiled, disk-cached ``njit`` component
    functions (not inlined): is a component compiled again when a new glue calls it, or is
    its cached code linked? How long does a cold glue take, against a glue whose components
    are inlined (``inline="always"``: numba types and lowers them again in every glue)?
(b) The cost per call of a component called without inlining (arrays and an integer
    offset passed, every function compiled without reference counting, as recipdyn's
    ``compiled`` does) against the same component inlined: a small one (a few operations,
    the size of a load's force law) and a heavy one (a generated expression of a few hundred
    operations, the size of a mechanism's accelerations).
(c) numba's first-class function values (``numba.types.FunctionType``) passed in a tuple to
    one generic compiled loop: their cost per call, and whether the loop compiles once for
    every configuration (two tuples of other functions of one length; a tuple of another
    length).

The components are synthetic (a heavy one is a generated straight-line expression of
``--terms`` operations, the shape of recipdyn's sympy kernels) so that the inlined and the
linked variants have the same body. A fourth measure takes recipdyn's own generated
free-crank accelerations (``_generated_drive``): a glue that calls them cold, with their
cache warm.

    python benchmarks/bench_composition.py [--terms 400] [--calls 2000000]

Prints one table; the numbers and the decision they led to are in docs/architecture.md
(Composing compiled components).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import textwrap


def _heavy_source(name: str, terms: int, inline: bool) -> str:
    """A straight-line expression of about ``terms`` operations on the state ``y[o:o+4]`` and
    the slice ``p[o:o+4]`` (generated like sympy's CSE output)."""
    opts = ", inline='always'" if inline else ""
    lines = [f"@nb.njit(cache=True{opts})",
             f"def {name}(t, y, p, o):",
             "    a0 = y[0] + p[o]", "    a1 = y[1] * p[o + 1]",
             "    a2 = math.sin(y[2]) + p[o + 2]",
             "    a3 = math.cos(y[3]) * p[o + 3]"]  # fmt: skip
    k = 4
    for i in range(terms // 4):
        a, b, c = f"a{k - 1}", f"a{k - 2}", f"a{k - 4}"
        op = ("+", "-", "*", "/")[i % 4]
        rhs = f"{a} {op} (1.0 + 0.5 * {b} * {b})" if op == "/" else f"{a} {op} 0.25 * {b} * {c}"
        if i % 7 == 0:
            rhs = f"math.sin({rhs})"
        lines.append(f"    a{k} = {rhs}")
        k += 1
    lines.append(f"    return a{k - 1} * 1e-3")
    return "\n".join(lines) + "\n"


def _component_module(terms: int) -> str:
    return "\n\n".join([
        "import math\nimport numba as nb\n",
        _heavy_source("heavy", terms, inline=False),
        _heavy_source("heavy_inline", terms, inline=True),
        "@nb.njit(cache=True)\ndef small(t, y, p, o):\n    return p[o] * y[0] + p[o + 1] * y[1]\n",
        "@nb.njit(cache=True, inline='always')\ndef small_inline(t, y, p, o):\n"
        "    return p[o] * y[0] + p[o + 1] * y[1]\n",
    ])  # fmt: skip


def _glue_module(stem: str, callee: str, tag: str, literal: bool = True) -> str:
    """A right-hand side in recipdyn's calling convention that calls ``callee`` twice with two
    offsets (two throws), compiled without reference counting; ``tag`` makes the module (and
    so its cache) new. ``literal``: the offsets as literals (numba types each as its own
    ``Literal[int]``), else as ``np.int64`` values."""
    o0, o1 = ("0", "4") if literal else ("np.int64(0)", "np.int64(4)")
    return textwrap.dedent(f'''
        # {tag}
        import numpy as np
        from recipdyn.model.base import RHS_SIGNATURE, compiled
        from comp import {callee} as f

        @compiled(RHS_SIGNATURE)
        def rhs(t, y, p, out):
            out[0] = f(t, y, p, {o0})
            out[1] = f(t, y, p, {o1})
            out[2] = y[0]
            out[3] = y[1]
        ''')  # fmt: skip


_RUN = r"""
import json, sys, time
sys.path.insert(0, {folder!r})
t0 = time.perf_counter()
import numba as nb
from recipdyn.model.base import RHS_SIGNATURE, RHS_TYPE
t_import = time.perf_counter() - t0
import importlib
out = {{}}
for mod, fn in {targets!r}:
    m = importlib.import_module(mod)
    d = getattr(m, fn)
    t0 = time.perf_counter()
    d.compile(RHS_SIGNATURE) if {kernel!r} else d.compile({component_sig})
    out[mod + "." + fn] = time.perf_counter() - t0
comp = importlib.import_module("comp") if {component!r} else None
stats = {{}}
if comp is not None:
    for fn in ("heavy", "small"):
        s = getattr(comp, fn).stats
        stats[fn] = [sum(s.cache_hits.values()), sum(s.cache_misses.values())]
print(json.dumps({{"times": out, "stats": stats}}))
"""

_COMPONENT_SIG = ("nb.types.float64(nb.types.float64, nb.types.float64[::1], "
                  "nb.types.float64[::1], nb.types.int64)")  # fmt: skip


def _script(folder: str, env: dict, code: str) -> dict:
    """Run ``code`` as a script file in ``folder`` (numba caches only functions of files) in a
    fresh process; its last line of output, JSON."""
    path = os.path.join(folder, "_script.py")
    with open(path, "w") as fh:
        fh.write(code)
    res = subprocess.run([sys.executable, path], env=env, capture_output=True, text=True,
                         check=False)  # fmt: skip
    if res.returncode:
        raise RuntimeError(res.stderr[-3000:])
    return json.loads(res.stdout.strip().splitlines()[-1])


def _run(folder: str, env: dict, targets, kernel: bool, component: bool = True) -> dict:
    code = _RUN.format(folder=folder, targets=targets, kernel=kernel, component=component,
                       component_sig=_COMPONENT_SIG)  # fmt: skip
    return _script(folder, env, code)


_PERCALL = r"""
import json, sys, time
sys.path.insert(0, {folder!r})
import numpy as np, numba as nb
from recipdyn.model.base import RHS_SIGNATURE, RHS_TYPE, typed
import importlib

@nb.njit(cache=True, _nrt=False)
def loop(rhs, y, p, out, n):
    s = 0.0
    for i in range(n):
        y[0] = 1e-6 * i
        rhs(0.0, y, p, out)
        s += out[0]
    return s

sig = nb.types.float64(RHS_TYPE, nb.types.float64[::1], nb.types.float64[::1],
                       nb.types.float64[::1], nb.types.int64)
lp = typed(loop, sig)
y = np.linspace(0.1, 0.4, 4); p = np.linspace(0.5, 1.2, 8); out = np.empty(4)
res = {{}}
for mod in {mods!r}:
    rhs = importlib.import_module(mod).rhs
    rhs.compile(RHS_SIGNATURE)
    lp(rhs, y, p, out, 1000)
best = {{m: 1e9 for m in {mods!r}}}
for r in range({rounds}):
    for mod in {mods!r}:
        rhs = importlib.import_module(mod).rhs
        t0 = time.perf_counter()
        lp(rhs, y, p, out, {calls})
        best[mod] = min(best[mod], (time.perf_counter() - t0) / {calls} * 1e9)
print(json.dumps(best))
"""


_FIRSTCLASS = r"""
import json, sys, time
sys.path.insert(0, {folder!r})
import numpy as np, numba as nb
import warnings
warnings.simplefilter("ignore", nb.errors.NumbaExperimentalFeatureWarning)
from numba import types as nbt
from recipdyn.model.base import RHS_SIGNATURE, RHS_TYPE, typed
import comp

csig = nbt.float64(nbt.float64, nbt.float64[::1], nbt.float64[::1], nbt.int64)
for fn in (comp.heavy, comp.small):
    fn.compile(csig)

@nb.njit(cache=True, _nrt=False)
def generic(fns, offs, t, y, p, out):
    for k in range(len(fns)):
        out[k] = fns[k](t, y, p, offs[k])

@nb.njit(cache=True, _nrt=False)
def loop(fns, offs, y, p, out, n):
    s = 0.0
    for i in range(n):
        y[0] = 1e-6 * i
        generic(fns, offs, 0.0, y, p, out)
        s += out[0]
    return s

FT = nbt.FunctionType(csig)
arr = nbt.float64[::1]
def lsig(n):
    return nbt.float64(nbt.UniTuple(FT, n), nbt.int64[::1], arr, arr, arr, nbt.int64)
res = {{}}
a = (comp.heavy, comp.heavy)
b = (comp.small, comp.small)
c = (comp.small, comp.small, comp.small)
y = np.linspace(0.1, 0.4, 4); p = np.linspace(0.5, 1.2, 12); out = np.empty(4)
offs = np.array([0, 4, 8], dtype=np.int64)
t0 = time.perf_counter()
loop.compile(lsig(2))
res["first_compile_s"] = time.perf_counter() - t0
loop.disable_compile()
loop(a, offs, y, p, out, 10)
loop(b, offs, y, p, out, 10)
res["same_length_other_functions_new_compilations"] = len(loop.signatures) - 1
try:
    loop(c, offs, y, p, out, 10)
    res["other_length"] = "ran without a compilation"
except TypeError:
    res["other_length"] = "needs its own compilation (another tuple type)"
best = {{"heavy": 1e9, "small": 1e9}}
for r in range({rounds}):
    for k, fns in (("heavy", a), ("small", b)):
        t0 = time.perf_counter()
        loop(fns, offs, y, p, out, {calls})
        best[k] = min(best[k], (time.perf_counter() - t0) / {calls} * 1e9)
res["ns_per_rhs"] = best
print(json.dumps(res))
"""


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--terms", type=int, default=400)
    ap.add_argument("--calls", type=int, default=2_000_000)
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--quick", action="store_true", help="a tenth of the calls, 3 rounds")
    args = ap.parse_args(argv)
    if args.quick:
        args.calls, args.rounds = args.calls // 10, 3

    with tempfile.TemporaryDirectory() as folder:
        env = {**os.environ, "NUMBA_CACHE_DIR": os.path.join(folder, "cache")}
        with open(os.path.join(folder, "comp.py"), "w") as fh:
            fh.write(_component_module(args.terms))
        glues = {
            "glue_heavy_linked": "heavy",
            "glue_heavy_inline": "heavy_inline",
            "glue_small_linked": "small",
            "glue_small_inline": "small_inline",
            "glue_heavy_linked_int64": "heavy",
            "glue_small_linked_int64": "small",
        }
        for stem, callee in glues.items():
            with open(os.path.join(folder, f"{stem}.py"), "w") as fh:
                fh.write(_glue_module(stem, callee, "first", not stem.endswith("int64")))

        print(f"numba cache: a fresh folder; heavy component: {args.terms} terms")
        # (a) a first glue compiles its components (cold); a second glue of the same
        # components, a new configuration, is then compiled with their cache warm
        for stem, callee in glues.items():
            with open(os.path.join(folder, f"{stem}_2.py"), "w") as fh:
                fh.write(_glue_module(stem, callee, "second", not stem.endswith("int64")))
        print(f"(a) {'glue':24s} {'first (s)':>9s} {'second (s)':>10s} {'reload (s)':>10s}  "
              "component cache (hits, misses) while the second compiles")  # fmt: skip
        for stem in glues:
            first = _run(folder, env, [(stem, "rhs")], kernel=True)
            second = _run(folder, env, [(f"{stem}_2", "rhs")], kernel=True)
            reload = _run(folder, env, [(f"{stem}_2", "rhs")], kernel=True)
            st = second["stats"]
            print(f"    {stem:24s} {first['times'][f'{stem}.rhs']:9.2f} "
                  f"{second['times'][f'{stem}_2.rhs']:10.2f} "
                  f"{reload['times'][f'{stem}_2.rhs']:10.2f}  heavy {st['heavy']}, "
                  f"small {st['small']}")  # fmt: skip
        # recipdyn's own generated free-crank accelerations, called by a new glue
        real = os.path.join(folder, "glue_real.py")
        with open(real, "w") as fh:
            fh.write(textwrap.dedent('''
                from recipdyn.model._generated_drive import free_crank_accelerations as fca
                from recipdyn.model.base import RHS_SIGNATURE, compiled

                @compiled(RHS_SIGNATURE)
                def rhs(t, y, p, out):
                    a1, ac = fca(t, (y[0], y[1], y[2], y[3]), p, (p[12], p[13], p[14]))
                    out[0] = y[2]
                    out[1] = y[3]
                    out[2] = a1
                    out[3] = ac
                '''))  # fmt: skip
        c1 = _run(folder, env, [("glue_real", "rhs")], kernel=True, component=False)
        with open(real, "a") as fh:
            fh.write("\n# another glue of the same parts\n")
        c2 = _run(folder, env, [("glue_real", "rhs")], kernel=True, component=False)
        t1, t2 = c1["times"]["glue_real.rhs"], c2["times"]["glue_real.rhs"]
        print(f"    recipdyn free-crank accelerations: first glue {t1:.2f}"
              f" s (the callee cold too), a second glue {t2:.2f} s "
              "(the callee's cache warm)")  # fmt: skip

        # (b) per call
        code = _PERCALL.format(folder=folder, mods=list(glues), rounds=args.rounds,
                               calls=args.calls)  # fmt: skip
        per = _script(folder, env, code)
        print(
            "(b) ns per right-hand side (two component calls), through the integrators' "
            "function type:"
        )
        for k in ("heavy", "small"):
            li, inl, i64 = (per[f"glue_{k}_linked"], per[f"glue_{k}_inline"],
                            per[f"glue_{k}_linked_int64"])  # fmt: skip
            print(f"    {k:6s} linked {li:7.1f}  linked, int64 offsets {i64:7.1f}  inlined "
                  f"{inl:7.1f}  ratio linked/inlined {li / inl:5.2f}")  # fmt: skip

        # (c) first-class function values in a tuple
        code = _FIRSTCLASS.format(folder=folder, rounds=args.rounds, calls=args.calls)
        fc = _script(folder, env, code)
        print(f"(c) first-class tuple loop: first compile {fc['first_compile_s']:.2f} s; new "
              "compilations for another tuple of the same length: "
              f"{fc['same_length_other_functions_new_compilations']}; a tuple of another "
              f"length: {fc['other_length']}")  # fmt: skip
        ns = fc["ns_per_rhs"]
        print(f"    ns per call of the generic loop (two component calls): heavy "
              f"{ns['heavy']:.1f}, small {ns['small']:.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
