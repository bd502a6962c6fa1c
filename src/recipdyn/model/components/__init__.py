"""Components the compressor is assembled from (contract: `.contract`).

Families: ``drive`` (`.drive`: prescribed speed or a motor, whose torque law is the
``motor`` family) and ``load`` (`.load`: the paper's load, a table, the ideal-valve
cycle). The mechanism with its crank-pin joint (the massless link, or the ideal joint at
rc = 0) is assembled with them by `recipdyn.model.compressor`.
"""

from .contract import Assembly, Component, check_fragments, glue_module
from .drive import DRIVES, MOTORS
from .load import LOADS, load_component

__all__ = ["Assembly", "Component", "check_fragments", "glue_module", "DRIVES", "MOTORS",
           "LOADS", "load_component"]  # fmt: skip
