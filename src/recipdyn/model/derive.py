r"""Euler–Lagrange equations for N generalized coordinates, compiled kernels from sympy.

Given the kinetic energy :math:`T(q, \dot q, t)`, the potential :math:`V(q, t)` and generalized
forces :math:`Q(q, \dot q, t)` (contact forces, gas pressure, damping — anything not in
:math:`V`), with :math:`L = T - V`:

.. math:: M(q, \dot q, t)\,\ddot q = b(q, \dot q, t),\qquad
          M_{ij} = \frac{\partial^2 L}{\partial \dot q_i \partial \dot q_j},\quad
          b_i = Q_i + \frac{\partial L}{\partial q_i}
                - \sum_j \frac{\partial^2 L}{\partial \dot q_i \partial q_j}\dot q_j
                - \frac{\partial^2 L}{\partial \dot q_i \partial t}.

The state is :math:`y = (q, \dot q)`. The right-hand side solves :math:`M \ddot q = b`; the exact
Jacobian uses :math:`\partial \ddot q/\partial y_k = M^{-1}(\partial b/\partial y_k -
(\partial M/\partial y_k)\,\ddot q)`, with every partial derivative taken symbolically. For one
coordinate the solve is a division; for more, ``numpy.linalg.solve`` inside the compiled kernel.

[`kernel_source`][recipdyn.model.derive.kernel_source] prints both kernels (numba, the calling
convention of [`recipdyn.model.base`][recipdyn.model.base], common subexpressions eliminated) as
Python source that is checked in; a test regenerates it and fails if the committed file is stale. A
model whose generalized forces come from numerical laws (the contact joint) uses
[`accelerations_source`][recipdyn.model.derive.accelerations_source] instead: ``qdd`` as a tuple,
the forces passed as a tuple, the mass matrix solved by a straight-line ``L D L^T``, so its
right-hand side allocates no arrays (a quarter of its cost before).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

__all__ = ["Lagrangian", "derive", "kernel_source", "accelerations_source", "system_source",
           "KernelPrinter"]  # fmt: skip


class KernelPrinter(PythonCodePrinter):
    """Prints half-integer powers with ``math.sqrt`` (no ``pow`` calls in the hot loop)."""

    def _print_Pow(self, expr, rational=False):
        b, e = expr.as_base_exp()
        if e.is_Rational and e.q == 2 and abs(e.p) <= 7:
            base = f"math.sqrt({self._print(b)})"
            mag = f"{base}**{abs(e.p)}" if abs(e.p) != 1 else base
            return f"(1.0/({mag}))" if e.p < 0 else f"({mag})"
        if e.is_Integer and e < 0:
            inner = self._print(b) if e == -1 else f"{self.parenthesize(b, 100)}**{-int(e)}"
            return f"(1.0/({inner}))"
        return super()._print_Pow(expr, rational=rational)


@dataclass(frozen=True)
class Lagrangian:
    """The derived equations ``M qdd = b`` and their partial derivatives.

    Attributes
    ----------
    q, qd : tuple of Symbol
        Coordinates and velocities (the state is ``(q, qd)``).
    t : Symbol
        Time.
    params : tuple of Symbol
        Parameters, in the order of the packed vector ``p``.
    M : Matrix (N x N)
    b : Matrix (N x 1)
    dM : list of Matrix
        ``dM[k] = dM/dy_k`` for each of the 2N state components.
    db : list of Matrix
        ``db[k] = db/dy_k``.
    """

    q: tuple[sp.Symbol, ...]
    qd: tuple[sp.Symbol, ...]
    t: sp.Symbol
    params: tuple[sp.Symbol, ...]
    M: sp.Matrix
    b: sp.Matrix
    dM: tuple[sp.Matrix, ...]
    db: tuple[sp.Matrix, ...]

    @property
    def n(self) -> int:
        return len(self.q)

    def accelerations(self) -> sp.Matrix:
        """``M^-1 b`` symbolically (for tests and small N)."""
        return self.M.LUsolve(self.b)


def derive(T: sp.Expr, V: sp.Expr, q: Sequence[sp.Symbol], qd: Sequence[sp.Symbol],
           t: sp.Symbol, params: Sequence[sp.Symbol],
           Q: Sequence[sp.Expr] | None = None) -> Lagrangian:  # fmt: skip
    """Euler–Lagrange equations of ``L = T - V`` with generalized forces ``Q`` (module doc).

    ``T``, ``V`` and ``Q`` are expressions in the symbols ``q``, ``qd``, ``t`` and ``params``;
    any other free symbol is an error (it would have no value in the compiled kernel).
    """
    q, qd, params = tuple(q), tuple(qd), tuple(params)
    n = len(q)
    if len(qd) != n:
        raise ValueError(f"{n} coordinates but {len(qd)} velocities")
    Q = [sp.S.Zero] * n if Q is None else [sp.sympify(x) for x in Q]
    if len(Q) != n:
        raise ValueError(f"{n} coordinates but {len(Q)} generalized forces")
    L = sp.sympify(T) - sp.sympify(V)
    allowed = {*q, *qd, t, *params}
    stray = (L.free_symbols | set().union(*(x.free_symbols for x in Q))) - allowed
    if stray:
        raise ValueError(f"symbols without a value: {sorted(map(str, stray))}")
    dL_dqd = [sp.diff(L, v) for v in qd]
    M = sp.Matrix(n, n, lambda i, j: sp.diff(dL_dqd[i], qd[j]))
    b = sp.Matrix(n, 1, lambda i, _: Q[i] + sp.diff(L, q[i])
                  - sum(sp.diff(dL_dqd[i], q[j]) * qd[j] for j in range(n))
                  - sp.diff(dL_dqd[i], t))  # fmt: skip
    y = (*q, *qd)
    dM = tuple(M.diff(v) for v in y)
    db = tuple(b.diff(v) for v in y)
    return Lagrangian(q, qd, t, params, M, b, dM, db)


def _names(lag: Lagrangian) -> dict[sp.Symbol, sp.Symbol]:
    sub = {}
    for i, s in enumerate(lag.q):
        sub[s] = sp.Symbol(f"_q{i}")
    for i, s in enumerate(lag.qd):
        sub[s] = sp.Symbol(f"_qd{i}")
    sub[lag.t] = sp.Symbol("t")
    for i, s in enumerate(lag.params):
        sub[s] = sp.Symbol(f"_p{i}")
    return sub


def _body(lag: Lagrangian, exprs: list[sp.Expr]) -> tuple[list[str], list[str]]:
    sub = _names(lag)
    repl, reduced = sp.cse([e.subs(sub) for e in exprs], symbols=sp.numbered_symbols("x"),
                           optimizations="basic")  # fmt: skip
    printer = KernelPrinter({"standard": "python3"})
    n = lag.n
    head = [f"    _q{i} = y[{i}]" for i in range(n)]
    head += [f"    _qd{i} = y[{n + i}]" for i in range(n)]
    head += [f"    _p{i} = p[{i}]" for i in range(len(lag.params))]
    head += [f"    {s} = {printer.doprint(e)}" for s, e in repl]
    return head, [printer.doprint(e) for e in reduced]


def _ldl_solve(n: int) -> list[str]:
    """Straight-line ``M x = b`` for a symmetric positive definite ``M`` (scalars ``m{i}{j}``,
    ``i >= j``, and ``b{i}``) by ``L D L^T`` without pivoting (stable for a mass matrix); the
    solution in ``a0 .. a{n-1}``."""
    out = []
    for j in range(n):
        out.append(f"    d{j} = m{j}{j}" + "".join(f" - l{j}{k} * ld{j}{k}" for k in range(j)))
        for i in range(j + 1, n):
            s = "".join(f" - l{i}{k} * ld{j}{k}" for k in range(j))
            out.append(f"    l{i}{j} = (m{i}{j}{s}) / d{j}")
            out.append(f"    ld{i}{j} = l{i}{j} * d{j}")
    for i in range(n):
        out.append(f"    z{i} = b{i}" + "".join(f" - l{i}{k} * z{k}" for k in range(i)))
    for i in reversed(range(n)):
        out.append(
            f"    a{i} = z{i} / d{i}" + "".join(f" - l{k}{i} * a{k}" for k in range(i + 1, n))
        )
    return out


def accelerations_source(lag: Lagrangian, name: str, inputs: int, given=()) -> str:
    """Python source of ``{name}_accelerations(t, y, p, u)``: ``qdd`` of ``M qdd = b`` as a
    tuple, allocating nothing (for a right-hand side called ~10^5 times a revolution).

    ``y`` holds ``(q, qd)`` (an array or a tuple), ``p`` the parameters except the last
    ``inputs``, which come from the tuple ``u`` (forces computed per call, e.g. contact laws).
    The solve is the straight-line ``L D L^T`` of the symmetric positive definite mass matrix.
    ``given``: subexpressions the caller has computed already (e.g. ``sin`` and ``cos`` of the
    crank angle), read from ``u`` after the inputs, in order. No imports: the caller's module
    provides ``nb`` and ``math`` (or ``np``)."""
    n = lag.n
    n_p = len(lag.params) - inputs
    low = [(i, j) for i in range(n) for j in range(i + 1)]
    names = [sp.Symbol(f"_g{i}") for i in range(len(given))]
    exprs = [lag.M[i, j] for i, j in low] + [lag.b[i] for i in range(n)]
    exprs = [e.subs(dict(zip(given, names, strict=True))) for e in exprs]
    head, vals = _body(lag, exprs)
    head[:0] = [f"    _g{i} = u[{inputs + i}]" for i in range(len(given))]
    for i in range(n_p, len(lag.params)):  # the inputs: from u, not p
        head[head.index(f"    _p{i} = p[{i}]")] = f"    _p{i} = u[{i - n_p}]"
    lines = ["@nb.njit(cache=True)", f"def {name}_accelerations(t, y, p, u):",
             '    """qdd of M qdd = b (a tuple; no arrays allocated)."""', *head]  # fmt: skip
    lines += [f"    m{i}{j} = {vals[k]}" for k, (i, j) in enumerate(low)]
    lines += [f"    b{i} = {vals[len(low) + i]}" for i in range(n)]
    lines += _ldl_solve(n)
    lines.append("    return (" + ", ".join(f"a{i}" for i in range(n)) + (",)" if n == 1 else ")"))
    return "\n".join(lines + [""])


def system_source(lag: Lagrangian, name: str, reads: dict, doc: str) -> str:
    """Python source of ``{name}_system(y, p, m, u)``: the lower triangle of the mass matrix
    and the right-hand side of ``M qdd = b`` as one tuple, ``(m00, m10, m11, ..., b0, b1,
    ...)``, allocating nothing: the parts of a body that an assembly combines with other
    bodies' (a throw's contribution to the crank's equation) before it solves.

    ``y`` holds ``(q, qd)`` (a tuple or an array); ``reads`` maps each parameter symbol to
    the text that reads it (``"p[m + 3]"``: the body's slice at offset ``m``; ``"u[0]"``: an
    input computed per call; ``"0.0"``: left out of this body, such as an inertia another
    body carries). No imports: the caller's module provides ``nb`` and ``math``."""
    n = lag.n
    low = [(i, j) for i in range(n) for j in range(i + 1)]
    zero = {s: sp.S.Zero for s, text in reads.items() if text == "0.0"}
    exprs = [lag.M[i, j].subs(zero) for i, j in low] + [lag.b[i].subs(zero) for i in range(n)]
    head, vals = _body(lag, exprs)
    used = set().union(*(e.free_symbols for e in exprs))
    for i, sym in enumerate(lag.params):
        line = f"    _p{i} = p[{i}]"
        if sym in zero or sym not in used:
            head.remove(line)
        else:
            head[head.index(line)] = f"    _p{i} = {reads[sym]}"
    lines = ["@nb.njit(cache=True)", f"def {name}_system(y, p, m, u):", f'    """{doc}"""',
             *head]  # fmt: skip
    lines += [f"    m{i}{j} = {vals[k]}" for k, (i, j) in enumerate(low)]
    lines += [f"    b{i} = {vals[len(low) + i]}" for i in range(n)]
    names = [f"m{i}{j}" for i, j in low] + [f"b{i}" for i in range(n)]
    lines.append("    return (" + ", ".join(names) + ")")
    return "\n".join(lines + [""])


def kernel_source(lag: Lagrangian, name: str, doc: str, *, jacobian: bool = True,
                  system_only: bool = False, header: bool = True) -> str:  # fmt: skip
    """Python source of ``{name}_system(t, y, p, M, b)``, ``{name}_rhs(t, y, p, out)`` and
    (with ``jacobian``) ``{name}_partials`` and ``{name}_jac(t, y, p, J)``.

    A model whose generalized forces are computed numerically (contact laws) uses
    ``{name}_system`` alone (``system_only``), with the forces as parameters, and solves
    ``M qdd = b`` itself. ``header=False`` leaves out the module docstring and imports (to put
    several systems in one module)."""
    n = lag.n
    m_exprs = [lag.M[i, j] for i in range(n) for j in range(n)]
    b_exprs = [lag.b[i] for i in range(n)]
    lines = [f'"""Generated by recipdyn.model.derive -- do not edit by hand.\n\n{doc}\n"""', "",
             "import math", "", "import numba as nb", "import numpy as np", "",
             "from recipdyn.model.base import JAC_SIGNATURE, RHS_SIGNATURE, compiled", "", "",
             "@nb.njit(cache=True)",
             f"def {name}_system(t, y, p, M, b):",
             '    """Fill M (N x N) and b (N) of M qdd = b."""']  # fmt: skip
    head, vals = _body(lag, m_exprs + b_exprs)
    lines += head
    for i in range(n):
        for j in range(n):
            lines.append(f"    M[{i}, {j}] = {vals[i * n + j]}")
    for i in range(n):
        lines.append(f"    b[{i}] = {vals[n * n + i]}")
    solve = "    acc[0] = b[0] / M[0, 0]" if n == 1 else "    acc[:] = np.linalg.solve(M, b)"
    if n == 2:  # Cramer's rule: no LAPACK call in the hot loop
        solve = ("    det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]\n"
                 "    acc[0] = (b[0] * M[1, 1] - M[0, 1] * b[1]) / det\n"
                 "    acc[1] = (M[0, 0] * b[1] - M[1, 0] * b[0]) / det")  # fmt: skip
    rhs_lines = ["", "", "@compiled(RHS_SIGNATURE, allocates=True)",
                 f"def {name}_rhs(t, y, p, out):",
                 '    """(qd, qdd) with M qdd = b."""',
                 f"    M = np.empty(({n}, {n}))", f"    b = np.empty({n})",
                 f"    acc = np.empty({n})", f"    {name}_system(t, y, p, M, b)", solve,
                 f"    for i in range({n}):", "        out[i] = y[" + str(n) + " + i]",
                 f"        out[{n} + i] = acc[i]"]  # fmt: skip
    if not header:
        lines = lines[lines.index("@nb.njit(cache=True)") :]
    if system_only:
        return "\n".join(lines + [""])
    if not jacobian:
        lines = [x.replace("JAC_SIGNATURE, RHS_SIGNATURE", "RHS_SIGNATURE") for x in lines]
        return "\n".join(lines + rhs_lines + [""])
    lines += ["", "", "@nb.njit(cache=True)", f"def {name}_partials(t, y, p, dM, db):",
              '    """dM[k] = dM/dy_k (2N x N x N), db[k] = db/dy_k (2N x N)."""']  # fmt: skip
    d_exprs = [lag.dM[k][i, j] for k in range(2 * n) for i in range(n) for j in range(n)]
    d_exprs += [lag.db[k][i] for k in range(2 * n) for i in range(n)]
    head, vals = _body(lag, d_exprs)
    lines += head
    for k in range(2 * n):
        for i in range(n):
            for j in range(n):
                lines.append(f"    dM[{k}, {i}, {j}] = {vals[k * n * n + i * n + j]}")
    off = 2 * n * n * n
    for k in range(2 * n):
        for i in range(n):
            lines.append(f"    db[{k}, {i}] = {vals[off + k * n + i]}")
    lines += rhs_lines
    lines += ["", "", "@compiled(JAC_SIGNATURE, allocates=True)", f"def {name}_jac(t, y, p, J):",
              '    """Exact Jacobian: dqdd/dy_k = M^-1 (db/dy_k - dM/dy_k qdd)."""',
              f"    M = np.empty(({n}, {n}))", f"    b = np.empty({n})", f"    acc = np.empty({n})",
              f"    dM = np.empty(({2 * n}, {n}, {n}))", f"    db = np.empty(({2 * n}, {n}))",
              f"    {name}_system(t, y, p, M, b)", solve,
              f"    {name}_partials(t, y, p, dM, db)",
              f"    for i in range({2 * n}):", f"        for k in range({2 * n}):",
              "            J[i, k] = 0.0",
              f"    for i in range({n}):", f"        J[i, {n} + i] = 1.0",
              f"    r = np.empty({n})", f"    for k in range({2 * n}):",
              f"        for i in range({n}):", "            s = db[k, i]",
              f"            for j in range({n}):", "                s -= dM[k, i, j] * acc[j]",
              "            r[i] = s",
              ("        col = r / M[0, 0]" if n == 1 else "        col = np.linalg.solve(M, r)"),
              f"        for i in range({n}):", f"            J[{n} + i, k] = col[i]",
              ""]  # fmt: skip
    return "\n".join(lines)
