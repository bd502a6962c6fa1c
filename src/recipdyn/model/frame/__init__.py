"""The frame on its elastic mounts: a rigid body in the horizontal plane that every throw shakes.

`.body` declares it (parameters, states, the mass, stiffness and damping matrices, its packed
slice, its energy, its motion at each throw's guide; the derivation and what it leaves out);
`.kernels` holds its compiled roles (a throw's shaking force as generalised forces on the
frame, the frame's derivatives), which the assembler binds in the templates when a machine
has a ``[frame]``. Nothing here but `.kernels` loads numba.
"""

from .body import MOUNT_PARAMS, PARAMS, STATES, WORK

__all__ = ["PARAMS", "MOUNT_PARAMS", "STATES", "WORK"]
