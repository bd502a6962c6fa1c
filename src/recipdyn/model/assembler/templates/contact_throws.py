"""Template of a machine's kernels whose throws have contact-impact (or lubricated) crank pins,
the crank turning at a prescribed speed.

Written per configuration like `prescribed` (the module docstring there): this file verbatim,
the block between the ``<bindings>`` markers replaced by the configuration's names and
constants. As it stands the block binds the reference configuration: one throw of the paper's
compressor with a worn crank pin, the module of which is the template `contact` itself.

Each throw is one joints' configuration (template `contact`: the module of its pins, its load
and its laws, the same for every throw of a machine) whose kernels read the throw's own slice
of the state and of the parameter vector: the template passes them views, ``y[s:s + n]``,
``p[o:o + m]``, ``out[s:s + n]`` (no copy, nothing allocated), so the joints' compiled parts
read a throw's slice as they read a one-throw model's vector. Each throw's slice holds its
own crank angle at ``t = 0`` (the shaft's plus its phase): with the crank prescribed the throws
do not interact, the right-hand side is the throws' side by side and the Jacobian is
block-diagonal (each block the throw's own, the complex step where the throw has it).

Roles (each a compiled function of the throw's module, called on the throw's views):
``throw_rhs(t, y, p, out)``, ``throw_jac(t, y, p, J)``, ``throw_event(t, y, p)``,
``throw_reset(t, y, p, out)``.

Constants: ``N_THROWS``; per throw ``k`` its first state ``THROW_STATE[k]`` and state count
``THROW_N[k]``, the offset of its slice ``THROW_PARAMS[k]`` and its length ``THROW_NP[k]``;
``OWN_EVENT``: the throws' own event functions are phased (they fall through 0 at an onset
*and* a separation, `recipdyn.model.joints.pins.phased_factor`: with a load with states, both
pins worn, or the guide's clearance) or there is one throw; else the machine's event is the
smallest of the throws' phased contact factors (``CFG``: the joints' configuration code, a
literal), since an onset factor alone (``|e| - c``) is negative in contact and would hide
the other throws' onsets in a minimum.
"""

import numba as nb
import numpy as np

from recipdyn.model.base import EVENT_SIGNATURE, JAC_SIGNATURE, RHS_SIGNATURE, compiled
from recipdyn.model.joints.pins import _flip, contact_factor

# isort: split
# <bindings>
from recipdyn.model.assembler.templates.contact import event as throw_event
from recipdyn.model.assembler.templates.contact import jac as throw_jac
from recipdyn.model.assembler.templates.contact import reset as throw_reset
from recipdyn.model.assembler.templates.contact import rhs as throw_rhs

CFG = 0
N_THROWS = np.int64(1)
OWN_EVENT = True
THROW_N = np.array([12], dtype=np.int64)
THROW_NP = np.array([33], dtype=np.int64)
THROW_PARAMS = np.array([0], dtype=np.int64)
THROW_STATE = np.array([0], dtype=np.int64)
# </bindings>


@nb.njit(cache=True)
def _rhs(t, y, p, out):
    for k in range(N_THROWS):
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        throw_rhs(t, y[s : s + n], p[o : o + m], out[s : s + n])


@compiled(RHS_SIGNATURE)
def rhs(t, y, p, out):
    _rhs(t, y, p, out)


@compiled(JAC_SIGNATURE, allocates=True)
def jac(t, y, p, J):
    """Block-diagonal: each throw's own Jacobian (its module's ``jac``) on its states; the
    throws do not interact with the crank prescribed."""
    for i in range(y.shape[0]):
        for j in range(y.shape[0]):
            J[i, j] = 0.0
    for k in range(N_THROWS):
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        block = np.zeros((n, n))
        throw_jac(t, y[s : s + n], p[o : o + m], block)
        for i in range(n):
            for j in range(n):
                J[s + i, s + j] = block[i, j]


@nb.njit(cache=True)
def _factor(t, y, p, k):
    """Throw ``k``'s event factor (positive between its events)."""
    s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
    if OWN_EVENT:
        return throw_event(t, y[s : s + n], p[o : o + m])
    return contact_factor(y[s : s + n], p[o : o + m], CFG)[0]


@compiled(EVENT_SIGNATURE)
def event(t, y, p):
    """The smallest of the throws' event factors."""
    low = np.inf
    for k in range(N_THROWS):
        low = min(low, _factor(t, y, p, k))
    return low


@compiled(RHS_SIGNATURE)
def reset(t, y, p, out):
    """The reset of every throw whose factor is the smallest (at the event) or below 0: two
    throws whose events coincide (identical throws in phase) change phase together; reset
    one by one, the other's factor would stay below 0 after the first reset and the event
    function, their minimum, would never cross 0 again. The other throws' states
    unchanged."""
    low = np.inf
    for k in range(N_THROWS):
        low = min(low, _factor(t, y, p, k))
    for i in range(y.shape[0]):
        out[i] = y[i]
    for k in range(N_THROWS):
        if _factor(t, y, p, k) > max(low, 0.0):
            continue
        s, n, o, m = THROW_STATE[k], THROW_N[k], THROW_PARAMS[k], THROW_NP[k]
        if OWN_EVENT:
            throw_reset(t, y[s : s + n], p[o : o + m], out[s : s + n])
        else:
            yk = y[s : s + n]
            pk = p[o : o + m]
            _flip(yk, contact_factor(yk, pk, CFG)[1], pk, out[s : s + n])
