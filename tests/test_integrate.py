"""Compiled integrators: agreement with SciPy, convergence order, events, failure handling."""

import dataclasses
import warnings

import numba as nb
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from recipdyn.errors import KernelAllocatesWarning
from recipdyn.integrate import IntegrationError, integrate
from recipdyn.model import CompressorParams, ODESystem, compressor_model
from recipdyn.model.base import EVENT_SIGNATURE, RHS_SIGNATURE, compiled


@nb.njit(RHS_SIGNATURE, cache=True)
def _oscillator(t, y, p, out):
    out[0] = y[1]
    out[1] = -p[0] * p[0] * y[0]


@nb.njit(RHS_SIGNATURE, cache=True)
def _blowup(t, y, p, out):
    out[0] = y[0] * y[0]


@nb.njit(EVENT_SIGNATURE, cache=True)
def _x_zero(t, y, p):
    return y[0]


OSC = ODESystem(rhs=_oscillator, params=np.array([2.0]), state_names=("x", "v"))


def test_dop853_matches_scipy_step_for_step():
    """Same algorithm and coefficients as scipy's DOP853: the same number of RHS evaluations
    (+-0.5 %, rounding differences in the step control), and a global error no larger than
    scipy's against a tight reference (the fast link oscillation accumulates phase error)."""
    m = compressor_model(CompressorParams(theta_c_offset=0.1))
    y0 = m.initial_state()
    T = m.period
    te = np.linspace(0, T, 1001)
    ours = integrate(m, y0, (0, T), t_eval=te, rtol=1e-9, atol=1e-12)
    sp_ = solve_ivp(m.f, (0, T), y0, method="DOP853", rtol=1e-9, atol=1e-12, t_eval=te)
    ref = integrate(m, y0, (0, T), t_eval=te, rtol=1e-13, atol=1e-14).y
    assert ours.nfev == pytest.approx(sp_.nfev, rel=5e-3)
    scale = np.abs(ref).max(axis=0)
    err_ours = np.max(np.abs(ours.y - ref) / scale)
    err_scipy = np.max(np.abs(sp_.y.T - ref) / scale)
    assert err_ours < 2 * err_scipy + 1e-9
    assert err_ours < 1e-5


def test_dense_output_matches_exact_solution():
    """Dense output at arbitrary times is 7th-order accurate: oscillator to ~1e-10."""
    te = np.sort(np.random.default_rng(1).uniform(0, 10, 500))
    sol = integrate(OSC, [1.0, 0.0], (0, 10), t_eval=te, rtol=1e-11, atol=1e-13)
    np.testing.assert_allclose(sol.y[:, 0], np.cos(2 * te), atol=1e-9)
    np.testing.assert_allclose(sol.y[:, 1], -2 * np.sin(2 * te), atol=2e-9)


def test_rk4_observed_order_is_four():
    """Halving h divides the RK4 global error by ~16: observed order 4 +- 0.3 (max error over
    a trajectory of a few link oscillations, against DOP853 at rtol 1e-13)."""
    m = compressor_model(CompressorParams(theta_c_offset=0.2))
    y0 = m.initial_state()
    t1 = 0.004
    te = np.linspace(0, t1, 41)
    ref = integrate(m, y0, (0, t1), t_eval=te, rtol=1e-13, atol=1e-14).y
    scale = np.abs(ref).max(axis=0)
    errs = []
    for n in (200, 400, 800):
        y = integrate(m, y0, (0, t1), t_eval=te, method="rk4", h=t1 / n).y
        errs.append(np.max(np.abs(y - ref) / scale))
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 4) < 0.3), orders


def test_rk4_and_dop853_agree():
    """The paper's fixed-step RK4 (fine step) and the adaptive method give the same motion."""
    p = CompressorParams(theta_c_offset=0.2)
    m = compressor_model(p)
    te = np.linspace(0, p.crank_period, 501)
    a = integrate(m, m.initial_state(), (0, p.crank_period), t_eval=te, rtol=1e-11)
    b = integrate(m, m.initial_state(), (0, p.crank_period), t_eval=te, method="rk4",
                  h=p.crank_period / 40000)  # fmt: skip
    assert np.max(np.abs(a.y[:, 0] - b.y[:, 0])) < 2e-5  # rad, after ~250 link oscillations


def test_chunked_run_is_reproducible_and_accurate():
    """Splitting a run for progress reporting changes results only within tolerance, and the
    same chunking gives bit-identical results."""
    te = np.linspace(0, 20, 101)
    one = integrate(OSC, [1.0, 0.0], (0, 20), t_eval=te)
    c1 = integrate(OSC, [1.0, 0.0], (0, 20), t_eval=te, chunks=7)
    c2 = integrate(OSC, [1.0, 0.0], (0, 20), t_eval=te, chunks=7)
    assert np.array_equal(c1.y, c2.y)
    np.testing.assert_allclose(one.y, c1.y, atol=1e-9)
    assert c1.t.shape == te.shape


def test_events_are_root_found_on_dense_output():
    """Zero crossings of x for x'' = -4x are at t = pi/4 + k pi/2, found to ~1e-12."""
    sol = integrate(OSC, [1.0, 0.0], (0, 10), event=_x_zero, rtol=1e-12, atol=1e-14)
    k = np.arange(sol.t_events.size)
    np.testing.assert_allclose(sol.t_events, np.pi / 4 + k * np.pi / 2, atol=1e-11)
    rising = integrate(OSC, [1.0, 0.0], (0, 10), event=_x_zero, event_direction=1)
    assert np.all(rising.y_events[:, 1] > 0)


@nb.njit(EVENT_SIGNATURE, cache=True)
def _near_crest(t, y, p):
    return y[0] - 0.95


@nb.njit(EVENT_SIGNATURE, cache=True)
def _far(t, y, p):
    return 100.0 + t


@pytest.mark.parametrize("rtol", [1e-3, 1e-4, 1e-6])
def test_two_crossings_inside_one_step_are_both_found(rtol):
    """x = cos 2t crosses 0.95 twice around each crest, 0.318 s apart; at rtol 1e-3 the steps
    are ~0.8 s, so both crossings lie inside one step. The cheap screen (cubic Hermite, 4th
    order) must still send these steps to the dense output: all 13 crossings in [0, 20] found,
    within the dense output's error at that tolerance (measured 5e-3 at rtol 1e-3)."""
    a = np.arccos(0.95) / 2
    k = np.arange(8) * np.pi
    exact = np.sort(np.r_[k + a, k[1:] - a])
    exact = exact[exact < 20]
    sol = integrate(OSC, [1.0, 0.0], (0, 20), event=_near_crest, rtol=rtol, atol=1e-9)
    if rtol == 1e-3:
        assert 20 / sol.nsteps > 2 * a  # the mean step is longer than a crossing pair
    assert sol.t_events.size == exact.size
    np.testing.assert_allclose(sol.t_events, exact, atol=5000 * rtol)


def test_an_event_far_from_zero_costs_no_rhs_calls():
    """Steps are screened on the free cubic interpolant: an event function that never turns
    toward zero adds no right-hand side calls and changes no step (before the screen, every
    step of a run with an event paid 3 calls for the dense output)."""
    plain = integrate(OSC, [1.0, 0.0], (0, 20), rtol=1e-9, atol=1e-12)
    ev = integrate(OSC, [1.0, 0.0], (0, 20), event=_far, rtol=1e-9, atol=1e-12)
    assert ev.t_events.size == 0
    assert ev.nsteps == plain.nsteps
    assert ev.nfev == plain.nfev
    np.testing.assert_array_equal(ev.y_final, plain.y_final)


def test_failure_raises_with_partial_solution():
    """A solution that blows up fails cleanly, keeping what was computed."""
    sys_ = ODESystem(rhs=_blowup, params=np.zeros(1), state_names=("y",))
    with pytest.raises(IntegrationError) as info:
        integrate(sys_, [1.0], (0, 2), t_eval=np.linspace(0, 2, 21))
    part = info.value.partial
    assert part is not None and 0 < part.t.size < 21 and part.t_final < 1.0 + 1e-6


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(method="euler"), "method"),
        (dict(rtol=0.0), "rtol"),
        (dict(method="rk4"), "step h"),
        (dict(t_span=(1.0, 0.0)), "t_span"),
    ],
)
def test_bad_solver_settings(kw, match):
    span = kw.pop("t_span", (0.0, 1.0))
    with pytest.raises(ValueError, match=match):
        integrate(OSC, [1.0, 0.0], span, **kw)


def test_dop853_tableau_from_the_user_cache_equals_scipy(tmp_path, monkeypatch):
    """The tableau is assembled from SciPy once and then read from the user's cache (so later
    runs skip importing scipy.integrate): both ways give SciPy's coefficients bit for bit, and a
    corrupt cache file is replaced, never used."""
    from scipy.integrate import DOP853 as S

    from recipdyn.integrate import tableaus

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "recipdyn" / "numba"))
    for attempt in ("built from scipy", "read from the cache", "corrupt file rebuilt"):
        if attempt == "corrupt file rebuilt":
            for f in (tmp_path / "recipdyn").glob("dop853-*.npz"):
                f.write_bytes(b"not an npz file")
        tableaus.dop853.cache_clear()
        tab = tableaus.dop853()
        n = S.n_stages
        assert np.array_equal(tab.A[:n, :n], S.A), attempt
        assert np.array_equal(tab.A[n, :n], S.B), attempt
        assert np.array_equal(tab.A[n + 1 :, :], S.A_EXTRA), attempt
        assert np.array_equal(tab.C, np.concatenate([S.C, [1.0], S.C_EXTRA])), attempt
        for k in ("B", "E3", "E5", "D"):
            assert np.array_equal(getattr(tab, k), getattr(S, k)), (attempt, k)
        assert (tab.order, tab.n_stages, tab.error_estimator_order) == (
            S.order, S.n_stages, S.error_estimator_order)  # fmt: skip
    assert len(list((tmp_path / "recipdyn").glob("dop853-*.npz"))) == 1
    tableaus.dop853.cache_clear()


def test_numba_cache_folder_follows_the_sources(tmp_path):
    """numba does not invalidate a cached caller when a compiled function it calls from another
    file changes; the cache folder is therefore keyed by a fingerprint of every module: a
    changed modification time of one module gives another folder, restoring it the same one,
    and a fresh process puts NUMBA_CACHE_DIR under the user's cache with that fingerprint."""
    import os
    import shutil
    import subprocess
    import sys

    import recipdyn

    fp = recipdyn._source_fingerprint()
    # a copy of the package is touched, never the sources other processes are running from
    copy = tmp_path / "copy" / "recipdyn"
    shutil.copytree(os.path.dirname(recipdyn.__file__), copy, copy_function=shutil.copy2,
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    valves = copy / "model" / "valves.py"
    before = recipdyn._source_fingerprint(str(copy))
    st = os.stat(valves)
    os.utime(valves, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))
    assert recipdyn._source_fingerprint(str(copy)) != before
    os.utime(valves, ns=(st.st_atime_ns, st.st_mtime_ns))
    assert recipdyn._source_fingerprint(str(copy)) == before
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    out = subprocess.run([sys.executable, "-c", "import os, recipdyn; "
                          "print(os.environ['NUMBA_CACHE_DIR'])"], env=env, check=True,
                         capture_output=True, text=True).stdout.strip()  # fmt: skip
    assert out == os.path.join(str(tmp_path), "recipdyn", "numba", fp)
    # numba imported before recipdyn (a script, a test module) reads the variable only when
    # it compiles: the kernels must still be cached in that folder, not beside the sources
    out = subprocess.run([sys.executable, "-c", "import numba, recipdyn; "
                          "from recipdyn.model import valves; "
                          "print(valves.state_force._cache._cache_path)"], env=env, check=True,
                         capture_output=True, text=True).stdout.strip()  # fmt: skip
    assert out.startswith(os.path.join(str(tmp_path), "recipdyn", "numba", fp))


def test_concurrent_cache_saves_keep_every_signature(tmp_path, monkeypatch):
    """Two writers saving two signatures of one function into numba's cache at once (parallel
    test workers or a process pool on a fresh machine): the second waits for the first, so
    the index keeps both entries, each naming its own code. Without the lock the second reads
    the index before the first has written it, both take the same data file, and one signature
    is lost or points at the other's code (model/base.py, _serialise_cache_saves)."""
    import threading

    from numba.core.caching import IndexDataCacheFile

    loaded, go = threading.Event(), threading.Event()
    plain = IndexDataCacheFile._load_index

    def load_then_wait(self):  # the first writer pauses between reading and writing the index
        out = plain(self)
        if threading.current_thread().name == "first":
            loaded.set()
            go.wait(timeout=10)
        return out

    monkeypatch.setattr(IndexDataCacheFile, "_load_index", load_then_wait)
    stamp = ("source", 1)
    writers = [IndexDataCacheFile(str(tmp_path), "f", stamp) for _ in range(2)]
    first = threading.Thread(target=writers[0].save, args=("sig one", "code one"), name="first")
    second = threading.Thread(target=writers[1].save, args=("sig two", "code two"))
    first.start()
    assert loaded.wait(timeout=10)
    second.start()
    second.join(timeout=1.0)  # it waits on the lock while the first holds it
    waited = second.is_alive()
    go.set()
    first.join(timeout=10)
    second.join(timeout=10)
    monkeypatch.setattr(IndexDataCacheFile, "_load_index", plain)
    index = IndexDataCacheFile(str(tmp_path), "f", stamp)
    assert waited
    assert index.load("sig one") == "code one"
    assert index.load("sig two") == "code two"


@compiled(RHS_SIGNATURE)
def _oscillator_allocating(t, y, p, out):
    tmp = np.empty(2)  # an allocation: not possible without reference counting
    tmp[0] = y[1]
    tmp[1] = -p[0] * p[0] * y[0]
    out[0] = tmp[0]
    out[1] = tmp[1]


@compiled(RHS_SIGNATURE, allocates=True)
def _oscillator_declared(t, y, p, out):
    tmp = np.empty(2)
    tmp[0] = y[1]
    tmp[1] = -p[0] * p[0] * y[0]
    out[0] = tmp[0]
    out[1] = tmp[1]


def test_a_kernel_that_allocates_still_works():
    """compiled() kernels are compiled without numba's reference counting (model/base.py),
    where allocation is impossible. One that allocates without saying so is compiled with
    counting instead, with a KernelAllocatesWarning naming it, and integrates like the same
    equations without allocation (to the bit: the same operations); declared with
    allocates=True it compiles without a warning."""
    y0 = np.array([1.0, 0.0])
    ref = integrate(OSC, y0, (0.0, 3.0), rtol=1e-10, atol=1e-12)
    alloc = ODESystem(rhs=_oscillator_allocating, params=OSC.params, state_names=("x", "v"))
    with pytest.warns(KernelAllocatesWarning, match="_oscillator_allocating allocates"):
        sol = integrate(alloc, y0, (0.0, 3.0), rtol=1e-10, atol=1e-12)
    assert _oscillator_allocating.targetoptions["_nrt"] is True
    np.testing.assert_array_equal(sol.y_final, ref.y_final)
    declared = ODESystem(rhs=_oscillator_declared, params=OSC.params, state_names=("x", "v"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", KernelAllocatesWarning)
        sol = integrate(declared, y0, (0.0, 3.0), rtol=1e-10, atol=1e-12)
    np.testing.assert_array_equal(sol.y_final, ref.y_final)


def test_contact_kernels_run_without_reference_counting():
    """The contact model's right-hand side and event run without reference counting (they
    allocate nothing; pyproject turns a fallback anywhere in the tests into an error), and
    a run gives, to the bit, what the same right-hand side compiled with counting gives: the
    flag removes the atomic counts of the array arguments, not arithmetic."""
    from recipdyn.model.registry import get_model

    m = get_model("compressor-contact")
    v = m.parameters(dict(e0_ratio=0.0))
    s = m.system(v)
    # the same source (the generated glue's), compiled with numba's default: reference counting
    counted = nb.njit(RHS_SIGNATURE)(s.rhs.py_func)
    y0 = m.initial_state(v)
    span = (0.0, 0.02)  # free flight, then impacts and sustained contact
    ours = integrate(s, y0, span, rtol=1e-10, atol=1e-14)
    plain = integrate(dataclasses.replace(s, rhs=counted), y0, span, rtol=1e-10, atol=1e-14)
    assert s.rhs.targetoptions["_nrt"] is False
    assert s.acting_event.function.targetoptions["_nrt"] is False
    assert ours.t_events.size >= 3 and ours.nsteps == plain.nsteps
    np.testing.assert_array_equal(ours.y_final, plain.y_final)
    np.testing.assert_array_equal(ours.t_events, plain.t_events)
