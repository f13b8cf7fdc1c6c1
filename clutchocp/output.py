"""Writing results: output folders, summary.json, CSV tables and PNG figures (shared by every command).

An output folder is written safely (:func:`output_folder`): the run writes into a private temporary
folder next to the target and renames it into place only when everything is written, so a folder
under the target's name is always complete; a second run aimed at the same folder while the first
is writing is refused; a target that cannot be written is refused before any solving.

Figures are drawn with matplotlib's object API on an Agg canvas, so no GUI backend is touched.
Nothing non-finite is ever written: a NaN or infinity in a result raises ModelError naming the key.
"""

import csv
import functools
import inspect
import json
import math
import os
import shutil
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import interrupt
from .errors import ModelError, OutputFolderError
from .plotting import finish

MARKER = ".clutchocp-result"   # written into every completed output folder
_ACTIVE = {}                   # temporary folder being written -> the target as the user wrote it


def check_output_folder(path, field="--out"):
    """Refuse, before any work, an output folder that cannot be written or must not be replaced.

    Allowed: a new folder (missing parents are created), an empty folder, or the folder of an
    earlier clutchocp run (it is replaced when the new run completes).

    Parameters
    ----------
    path : str or pathlib.Path
        The target folder.
    field : str
        Name of the option for the message.

    Returns
    -------
    pathlib.Path
        The target as an absolute path.

    Raises
    ------
    OutputFolderError
        Empty name; an existing file; a folder holding files that are not a clutchocp result
        (e.g. the current folder); a parent that is a file or not writable.
    """
    text = str(path)
    if not text.strip():
        raise OutputFolderError(f"{field}: empty folder name; give a folder for the results, e.g. {field} out/run1")
    target = Path(text).expanduser().absolute()
    if target.exists() or target.is_symlink():
        if not target.is_dir():
            raise OutputFolderError(f"{field} {text}: is an existing file, not a folder; give a folder name")
        if any(target.iterdir()) and not is_result_folder(target):
            raise OutputFolderError(f"{field} {text}: the folder exists and holds files that are not a clutchocp "
                                    "result (it would be replaced); give a new or empty folder")
    ancestor = target.parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputFolderError(f"{field} {text}: {ancestor} is a file, so the folder cannot be created there")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputFolderError(f"{field} {text}: no permission to write in {ancestor}; give a folder you can "
                                "write to")
    return target


def is_result_folder(path):
    """True if ``path`` holds the files of an earlier clutchocp run (its marker or a summary.json)."""
    path = Path(path)
    return (path / MARKER).exists() or (path / "summary.json").exists()


@dataclass
class OutputFolder:
    """The folder a run writes into: ``path`` (temporary, private) becomes ``target`` on success."""

    path: Path
    target: Path

    def final(self, file):
        """Where ``file`` (inside :attr:`path`) will be once the folder is in place."""
        return self.target / Path(file).relative_to(self.path)


def pid_alive(pid):
    """True if a process ``pid`` runs on this machine (a lock it holds is live)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _take_lock(lock, text, field):
    """Create the lock file of a target (holding our pid); refuse if a live run holds it."""
    for _ in range(2):
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            try:
                pid = int(lock.read_text().strip() or 0)
            except (OSError, ValueError):
                pid = 0
            if pid and pid_alive(pid):
                raise OutputFolderError(f"{field} {text}: another clutchocp run (process {pid}) is writing this "
                                        "folder; wait for it to finish or give another folder") from None
            lock.unlink(missing_ok=True)          # left behind by a run that was killed
            continue
        except OSError as exc:
            raise OutputFolderError(f"{field} {text}: cannot write next to the folder ({exc.strerror})") from None
        with os.fdopen(fd, "w") as fh:
            fh.write(str(os.getpid()))
        return
    raise OutputFolderError(f"{field} {text}: could not take the folder's lock {lock.name}; remove it if no run "
                            "is writing the folder")


@contextmanager
def output_folder(path, field="--out"):
    """Write a run's files safely: check the target, lock it, write privately, rename into place.

    Use it around the whole run (solve and writing), so that a bad target or a busy one is refused
    before any solving::

        with output_folder(args.out) as folder:
            run = simulate_engagement(scene)
            write_engagement(run, folder.path)

    On leaving the block normally the temporary folder replaces the target (an earlier result
    there is removed); on an error or Ctrl-C it is deleted and the target is left as it was.

    Parameters
    ----------
    path : str or pathlib.Path
        The target folder (see :func:`check_output_folder` for what is allowed).
    field : str
        Name of the option for messages.

    Yields
    ------
    OutputFolder
    """
    text = str(path)
    target = check_output_folder(path, field)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputFolderError(f"{field} {text}: cannot create {target.parent} ({exc.strerror})") from None
    lock = target.parent / f".{target.name}.lock"
    _take_lock(lock, text, field)
    temp = None
    try:
        try:
            temp = Path(tempfile.mkdtemp(prefix=f".{target.name}.partial-", dir=target.parent))
            umask = os.umask(0)
            os.umask(umask)
            os.chmod(temp, 0o777 & ~umask)           # mkdtemp makes it private (0700)
        except OSError as exc:
            raise OutputFolderError(f"{field} {text}: cannot create a folder in {target.parent} "
                                    f"({exc.strerror})") from None
        _ACTIVE[temp] = text
        yield OutputFolder(temp, target)
        interrupt.check("writing the results")
        try:
            (temp / MARKER).write_text("complete\n", encoding="utf-8")
            _replace(temp, target, text, field)
        except OSError as exc:
            raise OutputFolderError(f"{field} {text}: putting the results in place failed "
                                    f"({exc.strerror or exc})") from None
        temp = None
    finally:
        for key in [k for k, v in _ACTIVE.items() if v == text and k.parent == target.parent]:
            del _ACTIVE[key]
        if temp is not None:
            shutil.rmtree(temp, ignore_errors=True)
        lock.unlink(missing_ok=True)


def shown(path):
    """``path`` as the user will find it: a file in a folder being written is named in its target."""
    path = Path(path)
    for temp, text in _ACTIVE.items():
        if path.absolute() == temp or temp in path.absolute().parents:
            return str(Path(text) / path.absolute().relative_to(temp))
    return str(path)


def writes_folder(func):
    """Decorator: the function's ``out_dir`` is written through :func:`output_folder`.

    The target is checked and locked before the function runs, the function writes into the
    private temporary folder, and the folder is put in place when it returns. A call whose
    ``out_dir`` is already such a temporary folder (the command line opened it) is passed through.
    """
    signature = inspect.signature(func)

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        bound.apply_defaults()
        out_dir = bound.arguments["out_dir"]
        if Path(str(out_dir)).absolute() in _ACTIVE:
            return func(*bound.args, **bound.kwargs)
        with output_folder(out_dir) as folder:
            bound.arguments["out_dir"] = folder.path
            return func(*bound.args, **bound.kwargs)
    return wrapper


def _replace(temp, target, text, field):
    """Put the finished ``temp`` folder in place of ``target`` (moving an earlier result away first)."""
    old = None
    if target.exists():
        if not target.is_dir() or (any(target.iterdir()) and not is_result_folder(target)):
            raise OutputFolderError(f"{field} {text}: the folder was replaced by something that is not a "
                                    "clutchocp result while the run was going; results left unwritten")
        old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
        os.replace(target, old / "previous")
    os.replace(temp, target)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)


def write_csv(path, columns):
    """Write equal-length columns to a CSV file (header = column names, with units).

    Parameters
    ----------
    path : str or pathlib.Path
        File to write.
    columns : dict
        ``{"name [unit]": sequence}``; all sequences of the same length. Numbers must be finite.

    Returns
    -------
    pathlib.Path of the file.
    """
    path = Path(path)
    names = list(columns)
    data = [list(columns[n]) for n in names]
    lengths = {len(d) for d in data}
    if len(lengths) != 1:
        raise ModelError(f"{path.name}: columns of unequal length {sorted(lengths)}")
    for name, values in zip(names, data):
        for v in values:
            if isinstance(v, (float, np.floating)) and not math.isfinite(v):
                raise ModelError(f"{path.name}: non-finite value in column '{name}'")
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.writer(fh)
        writer.writerow(names)
        for row in zip(*data):
            writer.writerow([_fmt_csv(v) for v in row])
    return path


def _fmt_csv(v):
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.10g}"
    if isinstance(v, (np.integer,)):
        return str(int(v))
    return v


def new_figure(n_panels=1, width=6.4, height=4.2):
    """A matplotlib Figure on an Agg canvas with ``n_panels`` axes side by side.

    Returns
    -------
    fig, axes : Figure and a list of Axes.
    """
    # matplotlib (~0.3 s to import) loads with the first figure: the files of a run (CSV, JSON,
    # folders) and the engine that writes them (``Table.to_csv``) do not need it
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width * n_panels if n_panels > 1 else width, height), layout="constrained")
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(1, n_panels, k + 1) for k in range(n_panels)]
    return fig, axes


def save_figure(fig, path):
    """Save a figure as PNG (100 dpi) and return its path, with the shared conventions of
    :func:`clutchocp.plotting.finish` (plain tick labels, legends outside the data, wrapped titles)."""
    path = Path(path)
    finish(fig)
    fig.savefig(path, dpi=100)
    return path


def to_json_number(value, key):
    """A finite Python float/int/str/bool for summary.json; non-finite numbers raise ModelError."""
    if isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    value = float(value)
    if not math.isfinite(value):
        raise ModelError(f"summary key '{key}' is not a finite number ({value})")
    return value


def _clean(value, key):
    """A JSON-ready copy of ``value``: dicts and lists recursively, None kept, numbers finite."""
    if value is None:
        return None
    if isinstance(value, dict):
        return {str(k): _clean(v, f"{key}.{k}" if key else str(k)) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_clean(v, f"{key}[{i}]") for i, v in enumerate(value)]
    return to_json_number(value, key)


def nest(flat):
    """``{"a.b": 1}`` -> ``{"a": {"b": 1}}`` (split at the first dot)."""
    nested = {}
    for key, value in flat.items():
        head, dot, rest = key.partition(".")
        if dot:
            nested.setdefault(head, {})[rest] = value
        else:
            nested[key] = value
    return nested


def write_summary(path, summary):
    """Write ``summary.json`` (nested dicts; units in the key names; None becomes null).

    Returns
    -------
    pathlib.Path of the file.
    """
    path = Path(path)
    path.write_text(json.dumps(_clean(summary, ""), indent=2, sort_keys=True) + "\n", encoding="utf-8")
    return path
