"""Components the compressor is assembled from (contract: `.contract`).

Families: ``drive`` (`.drive`: prescribed speed or a motor, whose torque law is the
``motor`` family; their compiled functions in `.drive_kernels`) and ``load`` (`.load`: the
paper's load, a table, the ideal-valve cycle, the dynamic valves with their states). The
massless-link throw (`recipdyn.model.mechanism`) is assembled with them by the assembler
(`recipdyn.model.assembler`: a machine of one throw or several); the contact joints at each
pin (``crank_joint``, ``crosshead_joint``: ideal, dry contact, lubricated) by
`recipdyn.model.compressor_contact` (kernels: the assembler's templates ``joints`` and
``contact``; compiled parts: `recipdyn.model.joints.pins`; what it shares with the dynamic
valves' model: `.contact_model`). Nothing is imported here: the declarations (`.drive`)
load without numba, so a command line is checked before heavy imports.
"""
