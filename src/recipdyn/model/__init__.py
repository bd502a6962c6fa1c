"""Physical model: parameters, gas load, kinematics, equations of motion.

The names below are imported on first use (PEP 562): ``recipdyn.model.parameters`` and the
model registry load without numba, so that the command line validates input before it loads
any compiled code.
"""

from __future__ import annotations

import importlib

_LAZY = {
    "ODESystem": "base", "DiscreteMap": "base", "Signal": "base",
    "AssembledSystem": "assembler.system", "compressor_model": "assembler.model",
    "equilibrium_theta_c": "mechanism.link",
    "ideal_slider_crank": "kinematics", "ideal_mechanism": "kinematics",
    "joint_forces": "kinematics", "kinematics": "kinematics",
    "gas_force": "components.load", "mu_paper": "load", "read_load_table": "load",
    "ASSUMED": "parameters", "CompressorParams": "parameters", "ParameterError": "parameters",
    "paper_2d12": "parameters",
}  # fmt: skip

__all__ = list(_LAZY)


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        if name != "kinematics":  # the submodule of the same name keeps its attribute
            globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
