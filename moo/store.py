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

``<problem>`` and ``<variant>`` are file-name safe: the ``:`` of an import
path (``package.module:factory``) is written ``~``.

One writer, one setting
-----------------------
A results directory has one owner at a time: :func:`lock_results_dir` takes
an advisory lock (``fcntl.flock`` on ``<out>/.lock``, released by the kernel
when its holder exits or is killed); a second writer is refused with
:class:`ResultsDirBusyError`. Platforms without ``fcntl`` get no lock.

``<out>/settings.json`` records the directory's settings once, at its first
grid: :data:`DIR_FIELDS` (the budget, the population size asked for, the
MO-LSP cap and the base seed) for the whole directory, and
:data:`PROBLEM_FIELDS` (the problem, its objectives and set-up) for each
problem directory in it (``"problems": {<problem>: {...}}``; a directory may
hold several problems, each under one name). A later grid with other
settings is refused, naming the setting (:func:`check_settings`). A directory written before ``settings.json``
existed is checked against its records instead, and gets the file on its next
grid.

Reading
-------
:func:`load_records` validates every record (:func:`validate_record`: the
fields, ``F`` a non-empty finite ``|F| x n_obj`` matrix, the seed and the
variant those of its file and directory), refuses two records of one run
(duplicates), and refuses a directory mixing two settings
(:func:`check_consistent`); each error is a ``ValueError`` naming the file.

Writing
-------
Every output is written atomically (:func:`write_json_atomic`,
:func:`write_text_atomic`, :func:`atomic_path`): into a temporary file in
the target's directory, then ``os.replace``. A file under its final name is
always complete: killing the writer or a full disk loses at most the file in
flight and never leaves a truncated or empty file (the temporary file is
removed; the ``OSError`` propagates). Files get the usual mode
(``0666 & ~umask``, e.g. 0644). Only the driver writes; workers return
records, so they need no shared file system.
"""

from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import re
import stat
import tempfile
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX: no advisory lock
    fcntl = None  # type: ignore[assignment]

__all__ = ["write_json_atomic", "write_text_atomic", "atomic_path", "read_record", "validate_record",
           "load_records", "check_consistent", "check_output_file", "prepare_results_dir", "problem_dir",
           "variant_dir", "is_import_path", "safe_name", "lock_results_dir", "ResultsDirBusyError",
           "SettingsMismatchError", "settings_mismatch", "CorruptRecordError", "read_settings", "write_settings",
           "check_settings", "RECORD_NAME", "FAILED_SUFFIX", "SETTINGS_NAME", "DIR_FIELDS", "PROBLEM_FIELDS",
           "LOCK_NAME", "DISK_ERRORS"]

#: File names of finished-run records (``seed_<s>.json``).
RECORD_NAME = re.compile(r"^seed_(\d+)\.json$")
#: Suffix of a failure record beside the record's name: ``seed_<s>.failed.json``.
FAILED_SUFFIX = ".failed.json"
#: The directory's settings, written once (see the module docstring).
SETTINGS_NAME = "settings.json"
#: The lock file of :func:`lock_results_dir`.
LOCK_NAME = ".lock"
#: Fields of ``settings.json`` with one value for the whole directory.
DIR_FIELDS = ("budget", "pop_size", "max_leaders", "base_seed")
#: Fields of ``settings.json`` with one value per problem directory (under ``"problems"``).
PROBLEM_FIELDS = ("problem", "n_obj", "setup")

_REQUIRED = ("problem", "n_obj", "algorithm", "molsp", "seed", "F")


#: errno values of a write that failed for lack of room or rights (a disk error, not a failed run or executor).
DISK_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EACCES, errno.EPERM, errno.EIO})


class ResultsDirBusyError(ValueError):
    """Another process holds the lock of the results directory."""


class SettingsMismatchError(ValueError):
    """A run or a grid whose settings differ from those of the results directory (the message names them).

    ``where``, ``wrong`` (``(setting, recorded, this grid's)`` triples) and
    ``remedy`` are kept, so that a caller can name the settings its own way
    (the command line names its flags: ``--evals`` for ``budget``).
    """

    def __init__(self, where: str, wrong, remedy: str, names: dict[str, str] | None = None):
        self.where, self.wrong, self.remedy = where, [tuple(w) for w in wrong], remedy
        super().__init__(self.message(names))

    def message(self, names: dict[str, str] | None = None) -> str:
        """The message, each setting called by ``names.get(setting, setting)``."""
        names = names or {}
        what = ", ".join(f"{names.get(k, k)} {got!r} (this grid: {want!r})" for k, got, want in self.wrong)
        return f"{self.where} {what}; {self.remedy}"


def settings_mismatch(where: str, wrong, remedy: str) -> SettingsMismatchError:
    """The error for ``where`` holding other settings; ``wrong`` lists ``(name, recorded, this grid's)``."""
    return SettingsMismatchError(where, wrong, remedy)


class CorruptRecordError(ValueError):
    """A record that reads as JSON but is not a valid run record (the message names the file)."""


# ---------------------------------------------------------------------------- naming

def is_import_path(name: object) -> bool:
    """True for a string of the form ``module.path:factory`` (a colon marks an import path)."""
    return isinstance(name, str) and ":" in name


def safe_name(name: str) -> str:
    """``name`` as a file or directory name: an import path's ``:`` becomes ``~`` (portable)."""
    return name.replace(":", "~")


def problem_dir(problem: str, n_obj: int | None) -> str:
    """Directory name of a problem: its name (``:`` as ``~``), with ``-m<M>`` for DTLZ given ``n_obj``.

    An import path gets no ``-m<M>``: a directory holds one ``n_obj`` of it.
    """
    if is_import_path(problem):
        return safe_name(problem)
    key = problem.lower()
    return f"{key}-m{n_obj}" if n_obj is not None and key.startswith("dtlz") else key


def variant_dir(algorithm: str, molsp: bool) -> str:
    """Directory name of an algorithm variant: ``name`` or ``name+molsp`` (``:`` as ``~``)."""
    return safe_name(algorithm) + ("+molsp" if molsp else "")


# ---------------------------------------------------------------------------- atomic writes

def _umask() -> int:
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _special(path: Path) -> bool:
    """Whether ``path`` exists (through any symbolic link) and is not a regular file: a device, a FIFO, a socket."""
    try:
        return not stat.S_ISREG(os.stat(path).st_mode) and not stat.S_ISDIR(os.stat(path).st_mode)
    except OSError:
        return False


def _resolved(path: Path) -> Path:
    """``path`` with its symbolic links followed: the file a write replaces (the link itself stays)."""
    return Path(os.path.realpath(path)) if path.is_symlink() else path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on a clean exit it replaces ``path`` atomically.

    For writers that take a file name (``Figure.savefig``). The temporary
    file keeps ``path``'s suffix; it gets the usual mode (``0666 & ~umask``).
    On any error it is removed and ``path`` is left as it was. A symbolic
    link is written through (its target is replaced, the link stays); a
    device or a FIFO (``/dev/stdout``) is written directly, never replaced.
    """
    path = Path(path)
    if _special(path):
        yield path
        return
    path = _resolved(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}")
    try:
        try:
            os.fchmod(fd, 0o666 & ~_umask())
        finally:
            os.close(fd)
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically (temp file in the same directory, fsync, rename).

    The directory is created if needed. On any failure (a full disk: ``OSError``) the temporary file
    is removed and ``path`` is left as it was. A symbolic link is written through (its target is
    replaced atomically, the link stays); a device or a FIFO (``/dev/stdout``, ``/dev/null``) is
    written directly, never replaced (a write that fails there, ``/dev/full``, raises ``OSError``).
    """
    path = Path(path)
    if _special(path):
        with open(path, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
        return
    path = _resolved(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as fh:
        fh.write(text)
        fh.flush()
        os.fsync(fh.fileno())


def write_json_atomic(path: str | os.PathLike, data: dict) -> None:
    """Write ``data`` as JSON to ``path`` atomically (see :func:`moo.store.write_text_atomic`)."""
    write_text_atomic(path, json.dumps(data, indent=1) + "\n")


# ---------------------------------------------------------------------------- reading and validating

def read_record(path: str | os.PathLike, required: tuple[str, ...] = _REQUIRED) -> dict:
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


def _is_int(value: Any, minimum: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= minimum


def _front_problem(F: Any, n_obj: int) -> str | None:
    """Why ``F`` is not a non-empty finite ``|F| x n_obj`` list of rows (None if it is)."""
    if not isinstance(F, list) or not F:
        return "F is empty (a run's front has at least one point)" if isinstance(F, list) else \
            f"F must be a list of rows, got a JSON {type(F).__name__}"
    for i, row in enumerate(F):
        if not isinstance(row, list) or len(row) != n_obj:
            got = f"{len(row)} values" if isinstance(row, list) else f"a JSON {type(row).__name__}"
            return f"F row {i} must have {n_obj} values (n_obj), got {got}"
        for v in row:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                return f"F row {i} holds {v!r}, not a finite number"
    return None


def validate_record(rec: dict, path: str | os.PathLike | None = None) -> None:
    """``CorruptRecordError`` naming ``path`` unless ``rec`` is a valid run record.

    Checked: the identity fields' types, ``F`` a non-empty ``|F| x n_obj`` matrix of finite numbers
    (a finished run's front has at least one point), ``hv_ref_point`` ``n_obj`` numbers if present;
    and, for a file ``<problem>/<variant>/seed_<s>.json`` of a results directory, that ``s`` is the
    record's seed and ``<variant>`` its algorithm and variant.
    """
    where = "the record" if path is None else str(path)

    def bad(reason: str) -> CorruptRecordError:
        return CorruptRecordError(f"{where} is a corrupt run record: {reason}")

    missing = [k for k in _REQUIRED if k not in rec]
    if missing:
        raise bad(f"missing field(s) {', '.join(missing)}")
    if not _is_int(rec["n_obj"], 1):
        raise bad(f"n_obj must be a positive integer, got {rec['n_obj']!r}")
    if not _is_int(rec["seed"], 0):
        raise bad(f"seed must be a non-negative integer, got {rec['seed']!r}")
    if not isinstance(rec["problem"], str) or not isinstance(rec["algorithm"], str):
        raise bad("problem and algorithm must be strings")
    if not isinstance(rec["molsp"], bool):
        raise bad(f"molsp must be true or false, got {rec['molsp']!r}")
    reason = _front_problem(rec["F"], rec["n_obj"])
    if reason is not None:
        raise bad(reason)
    ref = rec.get("hv_ref_point")
    if ref is not None and _front_problem([ref], rec["n_obj"]) is not None:
        raise bad(f"hv_ref_point must be {rec['n_obj']} finite numbers, got {ref!r}")
    if path is not None:
        path = Path(path)
        m = RECORD_NAME.match(path.name)
        if m and int(m.group(1)) != rec["seed"]:
            raise bad(f"its seed {rec['seed']} differs from its file name")
        if m and path.parent.name != variant_dir(rec["algorithm"], rec["molsp"]):
            raise bad(f"it holds a run of {variant_dir(rec['algorithm'], rec['molsp'])}, "
                      f"not of its directory {path.parent.name}")


def load_records(out: str | os.PathLike, *, check: bool = True) -> list[dict]:
    """Every finished-run record under ``out`` (``*/*/seed_<s>.json``), sorted by path.

    Failure records and temporary files are skipped. Each record gets two
    extra keys: ``_path`` (its file) and ``_problem_dir``. A file that cannot
    be read as a record raises ``ValueError`` naming it; with ``check`` (the
    default) so does a corrupt record (:func:`validate_record`), a second
    record of one run, or a directory mixing two settings
    (:func:`check_consistent`).
    """
    out = Path(out)
    if not out.is_dir():
        raise ValueError(f"results directory {str(out)!r} does not exist")
    records = []
    seen: dict[tuple, str] = {}
    for path in sorted(p for p in out.glob("*/*/seed_*.json") if RECORD_NAME.match(p.name)):
        rec = read_record(path)
        if check:
            validate_record(rec, path)
            key = (rec["problem"], rec["n_obj"], rec.get("setup"), rec["algorithm"], rec["molsp"], rec["seed"])
            if key in seen:
                raise CorruptRecordError(f"{path} is a corrupt run record: a duplicate of {seen[key]} "
                                         "(the same run); remove one")
            seen[key] = str(path)
        rec["_path"] = str(path)
        rec["_problem_dir"] = path.parent.parent.name
        records.append(rec)
    if check:
        check_consistent(records, read_settings(out), out)
    return records


def _mixed(out: Any, field: str, a: Any, path_a: str, b: Any, path_b: str) -> ValueError:
    return ValueError(f"{path_b} holds a run with {field} {b!r}, but {path_a} has {a!r}: results directory "
                      f"{str(out)!r} mixes two settings; keep the runs of one setting in each directory")


def check_consistent(records: Iterable[dict], settings: dict | None = None, out: Any = "") -> None:
    """``ValueError`` naming a file unless the records share one setting.

    Across the directory the records share a budget, the MO-LSP runs a
    MO-LSP cap and the runs of one algorithm on one problem a population
    size; within a problem directory they share the problem, its objectives
    and its set-up. With the directory's ``settings`` (``settings.json``)
    they must also have its values. A record without a ``setup`` field
    (written before set-ups existed) matches any set-up.
    """
    first: dict[tuple, tuple[Any, str]] = {}
    if settings is not None:
        where = str(Path(out) / SETTINGS_NAME) if out else SETTINGS_NAME
        for k in ("budget", "max_leaders"):
            if k in settings:
                first[(k,)] = (settings[k], where)
        for pdir, entry in (settings.get("problems") or {}).items():
            for k in PROBLEM_FIELDS:
                if isinstance(entry, dict) and k in entry:
                    first[(k, pdir)] = (entry[k], where)
    for rec in records:
        path = rec.get("_path", "a record")
        pdir = rec.get("_problem_dir", "")
        items: list[tuple[tuple, Any]] = [((k, pdir), rec[k]) for k in PROBLEM_FIELDS if k in rec]
        items.append((("budget",), rec.get("budget")))
        if rec.get("molsp"):
            items.append((("max_leaders",), rec.get("max_leaders")))
        if "pop_size" in rec:
            items.append((("pop_size", pdir, rec["algorithm"]), rec["pop_size"]))
        for key, v in items:
            if key[0] == "setup" and v is None and settings is None:
                continue
            if key not in first:
                first[key] = (v, path)
            elif first[key][0] != v:
                a, where = first[key]
                raise _mixed(out, key[0] if key[0] != "pop_size" else f"pop_size of {key[2]}", a, where, v, path)


# ---------------------------------------------------------------------------- settings and lock

def read_settings(out: str | os.PathLike) -> dict | None:
    """The settings recorded in ``<out>/settings.json``, or None if there is none."""
    path = Path(out) / SETTINGS_NAME
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ValueError(f"{path} is not readable: {str(exc).splitlines()[0]}; it records the directory's "
                         "settings (remove it to have it rewritten from the next grid)") from None
    if not isinstance(data, dict):
        raise ValueError(f"{path} does not hold the directory's settings (a JSON object)")
    return data


def _persisted(recorded: dict | None, wanted: dict) -> dict:
    """``recorded`` with the problem of ``wanted`` (a flat dict of a grid's settings) added."""
    data = {k: wanted[k] for k in DIR_FIELDS} if recorded is None else dict(recorded)
    problems = dict(data.get("problems") or {})
    problems[wanted["problem_dir"]] = {k: wanted[k] for k in PROBLEM_FIELDS}
    data["problems"] = problems
    return data


def write_settings(out: str | os.PathLike, recorded: dict | None, wanted: dict) -> None:
    """Record the grid's settings ``wanted`` in ``<out>/settings.json`` (added to ``recorded``, if any).

    ``wanted`` is flat: the fields of :data:`DIR_FIELDS` and :data:`PROBLEM_FIELDS` and ``problem_dir``.
    """
    write_json_atomic(Path(out) / SETTINGS_NAME, _persisted(recorded, wanted))


def check_settings(out: str | os.PathLike, recorded: dict, wanted: dict) -> bool:
    """``ValueError`` naming ``settings.json`` and every setting where the grid's ``wanted`` differs.

    Returns True when the grid's problem is new to the directory (``settings.json`` is then to be
    rewritten with :func:`write_settings`). The same problem under another directory name (``dtlz2``
    and ``dtlz2-m3``) is refused: it would record each run twice.
    """
    wrong = [(k, recorded[k], wanted[k]) for k in DIR_FIELDS if k in recorded and recorded[k] != wanted[k]]
    problems = recorded.get("problems") or {}
    entry = problems.get(wanted["problem_dir"])
    if isinstance(entry, dict):
        wrong += [(k, entry[k], wanted[k]) for k in PROBLEM_FIELDS if k in entry and entry[k] != wanted[k]]
    else:
        for pdir, other in problems.items():
            if isinstance(other, dict) and (other.get("problem"), other.get("n_obj")) == \
                    (wanted["problem"], wanted["n_obj"]) and pdir != wanted["problem_dir"]:
                wrong.append(("problem directory", pdir, wanted["problem_dir"]))
    if wrong:
        raise settings_mismatch(f"{Path(out) / SETTINGS_NAME}: the directory holds runs with other settings:", wrong,
                                "use another out directory or the directory's settings")
    return entry is None


@contextlib.contextmanager
def lock_results_dir(out: str | os.PathLike) -> Iterator[None]:
    """Hold the advisory lock of the results directory ``out`` for the block.

    ``ResultsDirBusyError`` (a ``ValueError``) at once if another process
    holds it (no waiting). The kernel releases the lock when the holder exits
    or is killed. No lock where ``fcntl`` is missing (not POSIX).
    """
    if fcntl is None:  # pragma: no cover
        yield
        return
    path = Path(out) / LOCK_NAME
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            try:
                holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
            except OSError:
                holder = ""
            who = f" (process {holder})" if holder.isdigit() else ""
            raise ResultsDirBusyError(f"results directory {str(out)!r} is in use by another writer{who}; "
                                      "wait for it to finish or use another out directory") from None
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        yield
    finally:
        os.close(fd)                       # releases the lock


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
    file, so that read-only or virtual file systems such as ``/proc`` are caught). A symbolic
    link is checked at its target; a device or a FIFO (``/dev/stdout``) must be writable (it is
    written through, never replaced).
    """
    if not isinstance(path, (str, os.PathLike)) or not os.fspath(path):
        raise ValueError(f"{name} must be a file path, got {path!r}")
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{name}: {str(path)!r} is a directory, not a file")
    if _special(path):
        if not os.access(path, os.W_OK):
            raise ValueError(f"{name}: {str(path)!r} is not writable")
        return path
    parent = _resolved(path).absolute().parent
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
