"""The assembler: a machine description resolved once into compiled kernels with a named layout.

* `.assemble`: `assemble(machine, values)` -> `Configuration` (the components each part
  chose, the `Layout` of state, parameters and observer columns, the packed parameters, the
  generated kernels);
* `.layout`: named slices (``layout.state["throw2.theta_c"]``);
* `.generate` and ``templates/``: one module per configuration, from one template per drive
  whose only inputs are names and constants;
* `.model`: `MachineModel`, a machine as a model, and `OneThrow`, the compressor of one
  throw as ``--model compressor`` takes it.

Nothing is imported here: a machine's schema and layout load without numba.
"""
