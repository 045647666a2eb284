"""The README's tuning quick start runs as printed and ends with a certified design."""

import contextlib
import io
import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_tuning_quick_start_runs_and_certifies():
    text = README.read_text()
    section = text[text.index("## Tuning a controller"):text.index("## Reproducing the paper")]
    code = re.search(r"```python\n(.*?)```", section, flags=re.DOTALL).group(1)
    assert len(code.splitlines()) <= 25                # the limit for the quick start
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, str(README), "exec"), {"__name__": "readme"})
    assert out.getvalue().split()[-1] == "True"        # rc.robust_stability(...).certified of the chosen gain
