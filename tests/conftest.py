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
#: model and compiles each, a file that alone kept one worker busy for a third of the suite;
#: test_motor_lyapunov.py's tangent-flow cases are independent systems (one of them alone took
#: 136 s of a CI run).
SPLIT_BY_PARAMETER = ("tests/test_models.py", "tests/test_motor_lyapunov.py")

#: Work units (files, or a file's parameter) sent to the workers before all others, heaviest
#: first (seconds of one CI-like run on 2 workers, compiles included), so that no long unit
#: starts last while the other worker idles: by default xdist sends the files with the most
#: tests first, whatever they cost. The rest follow in xdist's order. A stale entry costs only
#: balance, never coverage.
HEAVIEST_FIRST = (
    "tests/test_motor_lyapunov.py[oil-and-contact]",  # 136 s
    "tests/test_motor_drive.py",  # ~150 s: the free-crank derivation's staleness 92 s
    "tests/test_contact_frame.py",  # ~110 s
    "tests/test_reproduce.py",  # the quick reproduction 62 s, its figures' checks
    "tests/test_contact.py",  # the derivation's staleness 49 s
    "tests/test_family.py",  # routes to the bit 35 s, a selector's record 27 s
    "tests/test_machine_lyapunov.py",  # 30-60 s
    "tests/test_motor_lyapunov.py",  # the huge flywheel 38 s
    "tests/test_diagnosis_baseline.py",
    "tests/test_diagnosis.py",
    "tests/test_faults.py",
    "tests/test_flexible_shaft.py",
    "tests/test_notebooks.py",
)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` keeps each test file on one worker (its module fixtures are computed
    once), except the files in `SPLIT_BY_PARAMETER`, whose tests go out by parameter id (the
    same model's tests together); the units of `HEAVIEST_FIRST` go out first. Other ``--dist``
    modes are xdist's own."""
    if config.getoption("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class _FileOrParameter(LoadFileScheduling):
        _ordered = False

        def _split_scope(self, nodeid: str) -> str:
            path = nodeid.split("::", 1)[0]
            if path.endswith(SPLIT_BY_PARAMETER) and nodeid.endswith("]"):
                return f"{path}[{nodeid.split('[', 1)[1]}"
            return path

        def _assign_work_unit(self, node) -> None:
            if not self._ordered:  # the queue is complete at the first assignment
                self._ordered = True
                for scope in reversed(HEAVIEST_FIRST):
                    if scope in self.workqueue:
                        self.workqueue.move_to_end(scope, last=False)
            super()._assign_work_unit(node)

    return _FileOrParameter(config, log)
