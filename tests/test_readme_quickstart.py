"""The README's quick start runs as printed, and what it prints holds by independent checks."""

import contextlib
import io
import re
from pathlib import Path

import control
import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def _run_quick_start():
    text = README.read_text()
    section = text[text.index("## Quick start"):text.index("## Documentation")]
    code = re.search(r"```python\n(.*?)```", section, flags=re.DOTALL).group(1)
    assert len(code.splitlines()) <= 25                # the limit for the quick start
    out = io.StringIO()
    namespace = {"__name__": "readme"}
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(README), "exec"), namespace)
    return out.getvalue().splitlines(), namespace


def _small_gain_margin(Acl, H, Ecl, n_freq=20001):
    """1 / max over a frequency grid of sigma_max(Ecl (e^{jw} I - Acl)^-1 H): numpy only."""
    z = np.exp(1j * np.linspace(0.0, np.pi, n_freq))[:, None, None]
    T = Ecl @ np.linalg.solve(z * np.eye(len(Acl)) - Acl, np.broadcast_to(H, (n_freq, *H.shape)))
    return 1.0 / np.linalg.norm(T, ord=2, axis=(1, 2)).max()


def test_readme_quick_start_runs_and_certifies():
    lines, ns = _run_quick_start()
    assert [line.split()[0] for line in lines] == ["lqr", "rlqr"]
    assert all(line.split()[-1] == "True" for line in lines)       # both certified, as the text says
    plant, unc, lqr, rlqr = ns["plant"], ns["unc"], ns["lqr"], ns["rlqr"]
    F, G, H, EF, EG = plant.F, plant.G, unc.H, unc.EF, unc.EG

    # the LQR is python-control's, with the opposite sign (u = K x)
    K_pc, _, _ = control.dlqr(F, G, ns["Q"], ns["R"])
    np.testing.assert_allclose(lqr.K, -K_pc, rtol=1e-8, atol=1e-10)

    # the printed LQR margin is the small-gain margin on a frequency grid, and "about 1.5" as the text says
    margin = float(lines[0].split()[1])
    Acl = F + G @ lqr.K
    np.testing.assert_allclose(margin, _small_gain_margin(Acl, H, EF + EG @ lqr.K), rtol=1e-4)
    assert 1.45 < margin < 1.55

    # the robust LQR cancels the uncertainty (the text's EF + EG K = 0): an infinite margin
    np.testing.assert_allclose(EF + EG @ rlqr.K, 0.0, atol=1e-9)
    assert lines[1].split()[1] == "inf"

    # certified means stable for every ||Delta|| <= 1: Delta is a scalar here, sweep [-1, 1]
    for K in (lqr.K, rlqr.K):
        for d in np.linspace(-1.0, 1.0, 201):
            rho = max(abs(np.linalg.eigvals(F + d * H @ EF + (G + d * H @ EG) @ K)))
            assert rho < 1.0
