"""Components the compressor is assembled from (contract: `.contract`).

Families: ``drive`` (`.drive`: prescribed speed or a motor, whose torque law is the
``motor`` family; their compiled functions in `.drive_kernels`) and ``load`` (`.load`: the
paper's load, a table, the ideal-valve cycle, the dynamic valves with their states). The
massless-link throw (`recipdyn.model.mechanism`) is assembled with them by the assembler
(`recipdyn.model.assembler`: a machine of one throw or several); the contact joints at each
pin (``crank_joint``, ``crosshead_joint``: ideal, dry contact, lubricated) are the joints'
configuration part `.contact_model` (derived in `recipdyn.model.compressor_contact`; kernels:
the assembler's templates ``joints`` and ``contact``; compiled parts:
`recipdyn.model.joints.pins`), which the assembler builds machines from too. Nothing is
imported here: the declarations (`.drive`) load without numba, so a command line is checked
before heavy imports.
"""
