"""The frame of a benchmark's result file: what, when, on what machine, under what load, by which command.

The files go to ``benchmarks/results/`` and are shown in the documentation as they are
(``docs/_ext/benchresults.py``), so each says how it was made.
"""

from __future__ import annotations

import datetime
import os
import platform
from pathlib import Path

__all__ = ["header", "write"]


def header(title: str, command: str) -> list[str]:
    """The first lines: the title, then date, machine, Python, cores, load average and the command."""
    return [f"# {title}", "",
            (f"{datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, {platform.machine()}, Python "
             f"{platform.python_version()}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at start "
             f"(shared machine). Command: `{command}`."), ""]


def write(lines: list[str], out: Path) -> None:
    """``lines`` and the load average at the end, written to ``out`` (its folder made if needed)."""
    lines = [*lines, "", f"Load average at the end: {os.getloadavg()[0]:.1f}."]
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n")
    print(f"written to {out}")
