"""Gases of the compression cycle (no imports: read by the parameter schemas, which must load
without numba so that a command line is checked before heavy imports)."""

__all__ = ["GASES"]

#: ``ideal`` (the polytropic model) or a CoolProp fluid (real-gas isentropes,
#: `recipdyn.model.realgas`).
GASES = ("ideal", "Air", "Nitrogen", "Oxygen", "Argon", "Helium", "Hydrogen", "Methane",
         "Ethane", "Propane", "CarbonDioxide", "R134a", "R410A", "Ammonia")  # fmt: skip
