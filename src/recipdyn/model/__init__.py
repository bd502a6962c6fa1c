"""Physical model: parameters, gas load, kinematics, equations of motion."""

from .base import DiscreteMap, ODESystem, Signal
from .compressor import CompressorModel, compressor_model, equilibrium_theta_c
from .kinematics import ideal_slider_crank, joint_forces, kinematics
from .load import gas_force, mu_paper, read_load_table
from .parameters import ASSUMED, CompressorParams, ParameterError, paper_2d12

__all__ = [
    "ODESystem", "DiscreteMap", "Signal", "CompressorModel", "compressor_model",
    "equilibrium_theta_c", "ideal_slider_crank", "joint_forces", "kinematics", "gas_force",
    "mu_paper", "read_load_table", "ASSUMED", "CompressorParams", "ParameterError", "paper_2d12",
]  # fmt: skip
