"""The run store: JSON run records on disk, written atomically, read back with errors that name the file.

Layout of a results directory (written by :func:`moo.experiment.run_experiment`)::

    <out>/<problem>/<variant>/seed_<s>.json          the record of a finished run
    <out>/<problem>/<variant>/seed_<s>.failed.json   a run that raised (its traceback)

``<variant>`` is the algorithm's registry name, with ``+molsp`` for its MO-LSP
version. A record is the JSON form of :class:`moo.runner.RunResult` (its
fields are listed there) plus ``run_index``, the run's position in the grid.
A failure record holds the run's settings (the same identity fields), the
exception as one line (``error``) and the full ``traceback``; a later
successful run of the same cell removes it.

Writes are atomic (:func:`write_json_atomic`): a file under its final name is
always complete, so killing the writer at any moment loses at most the run in
flight. Only the driver writes; workers return records, so they need no
shared file system.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import tempfile
from pathlib import Path

__all__ = ["write_json_atomic", "read_record", "load_records", "check_output_file", "prepare_results_dir",
           "RECORD_NAME", "FAILED_SUFFIX"]

#: File names of finished-run records (``seed_<s>.json``).
RECORD_NAME = re.compile(r"^seed_\d+\.json$")
#: Suffix of a failure record beside the record's name: ``seed_<s>.failed.json``.
FAILED_SUFFIX = ".failed.json"


def write_json_atomic(path: str | os.PathLike, data: dict) -> None:
    """Write ``data`` as JSON to ``path`` atomically (temp file in the same directory, fsync, rename).

    The directory is created if needed. On any failure the temporary file is
    removed and ``path`` is left as it was.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            json.dump(data, fh, indent=1)
            fh.write("\n")
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def read_record(path: str | os.PathLike, required: tuple[str, ...] = ("problem", "n_obj", "algorithm",
                                                                        "molsp", "seed", "F")) -> dict:
    """The record in ``path``; ``ValueError`` naming the file if it is not JSON or lacks a field of ``required``."""
    path = Path(path)
    try:
        rec = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ValueError(f"{path} is not a readable run record: {str(exc).splitlines()[0]}") from None
    if not isinstance(rec, dict):
        raise ValueError(f"{path} is not a run record: it holds a JSON {type(rec).__name__}, not an object")
    missing = [k for k in required if k not in rec]
    if missing:
        raise ValueError(f"{path} is not a run record: missing field(s) {', '.join(missing)}")
    return rec


def load_records(out: str | os.PathLike) -> list[dict]:
    """Every finished-run record under ``out`` (``*/*/seed_<s>.json``), sorted by path.

    Failure records and temporary files are skipped. Each record gets two
    extra keys: ``_path`` (its file) and ``_problem_dir``. A file that cannot
    be read as a record raises ``ValueError`` naming it.
    """
    out = Path(out)
    if not out.is_dir():
        raise ValueError(f"results directory {str(out)!r} does not exist")
    records = []
    for path in sorted(p for p in out.glob("*/*/seed_*.json") if RECORD_NAME.match(p.name)):
        rec = read_record(path)
        rec["_path"] = str(path)
        rec["_problem_dir"] = path.parent.parent.name
        records.append(rec)
    return records


def _probe_directory(directory: Path, name: str) -> None:
    """``ValueError`` unless a file can be created in ``directory`` (tried with a temporary file)."""
    try:
        fd, tmp = tempfile.mkstemp(dir=directory, prefix=".moo-write-test.")
    except OSError as exc:
        raise ValueError(f"{name}: cannot write in {str(directory)!r} ({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(tmp)


def check_output_file(path: str | os.PathLike, name: str = "out") -> Path:
    """``path`` as a :class:`~pathlib.Path`, checked before any work to be writable as a file.

    Not empty, not a directory, its directory existing and writable (tried with a temporary
    file, so that read-only or virtual file systems such as ``/proc`` are caught).
    """
    if not isinstance(path, (str, os.PathLike)) or not os.fspath(path):
        raise ValueError(f"{name} must be a file path, got {path!r}")
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{name}: {str(path)!r} is a directory, not a file")
    parent = path.absolute().parent
    if not parent.is_dir():
        raise ValueError(f"{name}: directory {str(parent)!r} does not exist")
    _probe_directory(parent, name)
    return path


def prepare_results_dir(out: str | os.PathLike, name: str = "out") -> Path:
    """Create the results directory ``out`` if needed and check that files can be written in it."""
    if not isinstance(out, (str, os.PathLike)) or not os.fspath(out):
        raise ValueError(f"{name} must be a directory path, got {out!r}")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"{name}: {str(out)!r} exists and is not a directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"{name}: cannot create directory {str(out)!r} ({exc.strerror or exc})") from None
    _probe_directory(out, name)
    return out
