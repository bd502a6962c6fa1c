"""recipdyn animate: the drawn mechanism is the model's geometry; the GIF has its frames."""

import numpy as np
import pytest
import xarray as xr
from PIL import Image

from recipdyn.animate import mechanism_points
from recipdyn.cli import main


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    path = tmp_path_factory.mktemp("anim") / "run.nc"
    assert main(["simulate", "--rc", "1 mm", "--d", "1 mm", "--set", "theta_c_offset=0.2",
                 "-n", "1", "--fs", "4 kHz", "-o", str(path), "--no-figure",
                 "--no-progress"]) == 0  # fmt: skip
    return path


def test_mechanism_at_true_scale_is_the_models(run):
    """Unmagnified, the drawn crosshead sits on its guide (y = -d) at the record's x3, the
    rod has its length and the link the clearance: the closure is the model's (to rounding)."""
    with xr.open_dataset(run) as ds:
        a = ds.attrs
        m = mechanism_points(ds["theta1"].values, ds["theta_c"].values, r=a["param_r"],
                             l=a["param_l"], rc=a["param_rc"], d=a["param_d"])  # fmt: skip
        np.testing.assert_allclose(m.C[:, 0], ds["x"].values, rtol=0, atol=1e-12)
        np.testing.assert_allclose(np.arctan2(*(m.C - m.J)[:, ::-1].T), ds["theta2"].values,
                                   rtol=0, atol=1e-12)  # fmt: skip
        np.testing.assert_allclose(m.C[:, 1], -a["param_d"], rtol=0, atol=1e-15)
        np.testing.assert_allclose(np.hypot(*(m.J - m.B).T), a["param_rc"], rtol=1e-12)
        k = 40.0
        geo = dict(r=a["param_r"], l=a["param_l"], rc=a["param_rc"], d=a["param_d"])
        mk = mechanism_points(ds["theta1"].values, ds["theta_c"].values, **geo, exaggerate=k)
        np.testing.assert_allclose(np.hypot(*(mk.C - mk.J).T), a["param_l"], rtol=1e-12)
        np.testing.assert_allclose(mk.C[:, 1], -k * a["param_d"], rtol=0, atol=1e-15)


def test_animate_writes_a_gif(run, tmp_path):
    out = tmp_path / "m.gif"
    assert main(["animate", str(run), "-o", str(out), "-n", "0.25", "--frames-per-revolution",
                 "24", "--no-progress"]) == 0  # fmt: skip
    with Image.open(out) as im:
        assert im.n_frames == 6
        assert im.size[0] >= 400


@pytest.mark.parametrize("args,word", [
    (["-o", "x.avi"], "extension"),
    (["--exaggerate", "0.5"], "exaggerate"),
    (["--exaggerate", "1e6"], "exaggerate"),
    (["--fps", "0"], "fps"),
])  # fmt: skip
def test_animate_bad_input(run, tmp_path, capsys, args, word):
    args = [str(tmp_path / a) if a.endswith(".avi") else a for a in args]
    if "-o" not in args:
        args += ["-o", str(tmp_path / "x.gif")]
    assert main(["animate", str(run), *args, "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err
