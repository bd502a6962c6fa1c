import os

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
os.environ.setdefault("MPLBACKEND", "Agg")


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def generalized_mass(p):
    """``A(theta1, theta_c)``: the compressor's generalized mass (Lagrangian coefficient of
    theta_c''), from the symbolic derivation, for parameters ``p`` (a test helper)."""
    import sympy as sp

    from recipdyn.model.derivation import SYMBOLS as S
    from recipdyn.model.derivation import structured_equations

    values = {S["r"]: p.r, S["l"]: p.l, S["ls"]: p.ls, S["m2"]: p.m2, S["m3"]: p.m3,
              S["J2"]: p.J2, S["rc"]: p.rc, S["d"]: p.d}  # fmt: skip
    return sp.lambdify((S["theta1"], S["theta_c"]), structured_equations()["A"].subs(values),
                       "numpy")  # fmt: skip


#: Test files spread over the parallel workers (``make test``: ``--dist loadfile``) one
#: parameter at a time instead of whole: test_models.py runs every check on every registered
#: model and compiles each, a file that alone kept one worker busy for a third of the suite.
SPLIT_BY_PARAMETER = ("tests/test_models.py",)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` keeps each test file on one worker (its module fixtures are computed
    once), except the files in `SPLIT_BY_PARAMETER`, whose tests go out by parameter id (the
    same model's tests together). Other ``--dist`` modes are xdist's own."""
    if config.getoption("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class _FileOrParameter(LoadFileScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = nodeid.split("::", 1)[0]
            if path.endswith(SPLIT_BY_PARAMETER) and nodeid.endswith("]"):
                return f"{path}[{nodeid.split('[', 1)[1]}"
            return path

    return _FileOrParameter(config, log)
