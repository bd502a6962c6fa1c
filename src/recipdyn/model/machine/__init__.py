"""A machine as a description: its crankshaft and drive, its throws, stages, interstage
volumes and sensors.

`Machine` (`.description`) says what a machine is made of — which part at each place, and the
values of their parameters — and nothing of how it is computed: the assembler
(`recipdyn.model.assembler`) resolves it into a configuration with a named layout and its
compiled kernels, and `recipdyn.model.assembler.model.MachineModel` makes it a model every
layer above uses. A machine is written in a TOML file (`read_machine`;
``recipdyn simulate --machine FILE.toml``) or built from the same Python objects. Its
parameters are namespaced (``throw2.rc``, ``shaft.J_drive``, ``stage1.suction_pressure``); a
machine of one throw keeps the compressor's names (``rc``, ``omega``). Nothing here loads
numba.
"""

from .description import (
    Frame,
    Interstage,
    Machine,
    Mount,
    Sensor,
    Shaft,
    Stage,
    Throw,
    read_machine,
)

__all__ = ["Machine", "Shaft", "Throw", "Stage", "Interstage", "Sensor", "Frame", "Mount",
           "read_machine"]  # fmt: skip
