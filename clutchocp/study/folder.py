"""The output folder of a study: a lock against concurrent sweeps, and results streamed row by row.

``results.csv`` gets one complete line per finished point, flushed at once, so an interrupted
sweep keeps every finished point; a resumed sweep reads the file back and skips the points whose
``point_id`` (a name of their parameters, :func:`~clutchocp.study.points.point_id`) is present.
A half-written last line (the process killed mid-write) is dropped on resume. ``calibration.csv``
(optimize) holds the optimal command of each solved point, written before its results row.

``sweep.lock`` (created exclusively, holding the process id and host) makes a second sweep into
the same folder stop with one line while the first runs; a lock left by a process that no longer
exists on this host is taken over. ``study.json`` records what the folder holds, so a sweep with
other fields, task or scene is refused instead of mixing its rows in.
"""

import csv
import json
import math
import os
import socket
import time
from pathlib import Path

from ..errors import ClutchocpError
from ..output import pid_alive

RESULTS = "results.csv"
CALIBRATION = "calibration.csv"
LOCK = "sweep.lock"
SPEC = "study.json"
TEXT_COLUMNS = ("point_id", "status", "reason", "final_mode")     # kept as text when read back


class StudyFolderError(ClutchocpError, OSError):
    """The output folder is in use by another sweep, or holds something else."""


def format_cell(value):
    """CSV text of a value: floats round-trip exactly (repr), None and non-finite numbers empty."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):                   # numpy floats too; repr(float) round-trips exactly
        return repr(float(value)) if math.isfinite(value) else ""
    return str(value)


def parse_cell(text):
    """Inverse of :func:`format_cell`: number, bool, None (empty) or the text."""
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    try:
        return float(text)
    except ValueError:
        return text


class StudyFolder:
    """The folder a study writes into, locked for the lifetime of this object (use ``with``).

    Parameters
    ----------
    path : str or pathlib.Path
        Output folder (created if missing).
    spec : dict
        What the study is (scene, task, fields, options): written to ``study.json``; a folder
        holding another study is refused.
    columns : sequence of str
        Columns of ``results.csv`` in order.
    """

    def __init__(self, path, spec, columns):
        self.path = Path(path)
        self.spec = json.loads(json.dumps(spec))
        self.columns = list(columns)
        self._lock = self.path / LOCK
        self._results = None
        self._calibration = None

    # -- lock -------------------------------------------------------------------------------------
    def __enter__(self):
        if self.path.exists() and not self.path.is_dir():
            raise StudyFolderError(f"--out {self.path}: exists and is not a folder")
        self.path.mkdir(parents=True, exist_ok=True)
        self._acquire()
        try:
            self._check_spec()
        except BaseException:
            self._release()
            raise
        return self

    def __exit__(self, *exc):
        for fh in (self._results, self._calibration):
            if fh is not None:
                fh.close()
        self._release()
        return False

    def _acquire(self):
        me = f"{os.getpid()} {socket.gethostname()} {time.strftime('%Y-%m-%dT%H:%M:%S')}\n"
        for _ in range(2):
            try:
                fd = os.open(self._lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                owner = self._lock.read_text(encoding="utf-8", errors="replace").split()
                pid, host = (int(owner[0]), owner[1]) if len(owner) >= 2 and owner[0].isdigit() else (None, None)
                if pid is not None and host == socket.gethostname() and not pid_alive(pid):
                    self._lock.unlink(missing_ok=True)          # left by a sweep that no longer runs
                    continue
                who = f"process {pid} on {host}" if pid is not None else "another process"
                raise StudyFolderError(f"--out {self.path}: another sweep ({who}) is writing into this folder "
                                       f"({LOCK}); wait for it to finish or choose another --out") from None
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(me)
            return
        raise StudyFolderError(f"--out {self.path}: could not take {LOCK}")

    def _release(self):
        try:
            owner = self._lock.read_text(encoding="utf-8").split()
        except FileNotFoundError:
            return
        if owner and owner[0] == str(os.getpid()):
            self._lock.unlink(missing_ok=True)

    def _check_spec(self):
        spec_file = self.path / SPEC
        if spec_file.is_file():
            held = json.loads(spec_file.read_text(encoding="utf-8"))
            if held != self.spec:
                diff = sorted(k for k in set(held) | set(self.spec) if held.get(k) != self.spec.get(k))
                raise StudyFolderError(f"--out {self.path}: holds another sweep (differs in {', '.join(diff)}); "
                                       "choose another --out to start a new one, or repeat that sweep's command "
                                       "to resume it")
            return
        others = [p.name for p in self.path.iterdir() if p.name != LOCK]
        if others:
            listed = ", ".join(sorted(others)[:3]) + (" ..." if len(others) > 3 else "")
            raise StudyFolderError(f"--out {self.path}: is not empty and holds no sweep ({listed}); "
                                   "choose an empty or new folder")
        spec_file.write_text(json.dumps(self.spec, indent=2, sort_keys=True) + "\n", encoding="utf-8")

    # -- results ----------------------------------------------------------------------------------
    def finished(self):
        """Rows already in ``results.csv`` (parsed), after dropping a half-written last line.

        Also drops calibration rows of points that have no results row (written just before
        an interruption).
        """
        rows = read_complete(self.path / RESULTS, self.columns)
        done = {row["point_id"] for row in rows}
        calibration = self.path / CALIBRATION
        if calibration.is_file():
            with calibration.open(newline="", encoding="utf-8") as fh:
                header = next(csv.reader(fh), None)
            if header:
                kept = [r for r in read_complete(calibration, header) if r["point_id"] in done]
                _rewrite(calibration, header, kept)
        return rows

    def append(self, row):
        """Write one complete results row and flush it to the file."""
        if self._results is None:
            self._results = _open_append(self.path / RESULTS, self.columns)
        _write_line(self._results, [format_cell(row.get(c)) for c in self.columns])

    def append_curve(self, row, curve, fields):
        """Write the optimal command of one point into ``calibration.csv`` (one line per time)."""
        header = list(fields) + ["point_id", "time_s", "pressure_Pa"]
        if self._calibration is None:
            self._calibration = _open_append(self.path / CALIBRATION, header)
        writer = csv.writer(self._calibration, lineterminator="\n")
        for t, p in zip(curve["time_s"], curve["pressure_Pa"]):
            cells = [format_cell(row.get(f)) for f in fields] + [row["point_id"], format_cell(t), format_cell(p)]
            writer.writerow(cells)
        self._calibration.flush()


def _write_line(fh, cells):
    writer = csv.writer(fh, lineterminator="\n")
    writer.writerow(cells)
    fh.flush()


def _open_append(path, header):
    """Open ``path`` for appending; write the header if the file is new or empty."""
    new = not path.is_file() or path.stat().st_size == 0
    fh = path.open("a", newline="", encoding="utf-8")
    if new:
        _write_line(fh, header)
    return fh


def read_complete(path, columns):
    """Parsed rows of a CSV written by this module; a last line without its newline is cut off."""
    if not path.is_file():
        return []
    data = path.read_bytes()
    end = data.rfind(b"\n") + 1
    if end < len(data):
        with path.open("r+b") as fh:          # a line cut by an interruption: drop it
            fh.truncate(end)
        data = data[:end]
    lines = data.decode("utf-8").splitlines()
    if not lines:
        return []
    header = next(csv.reader([lines[0]]))
    if header != list(columns):
        raise StudyFolderError(f"{path}: its columns differ from this sweep's; choose another --out")
    return [{name: cell if name in TEXT_COLUMNS else parse_cell(cell) for name, cell in zip(header, cells)}
            for cells in csv.reader(lines[1:]) if len(cells) == len(header)]


def _rewrite(path, header, rows):
    partial = path.with_suffix(".tmp")
    with partial.open("w", newline="", encoding="utf-8") as fh:
        _write_line(fh, header)
        for row in rows:
            _write_line(fh, [format_cell(row[c]) for c in header])
    partial.replace(path)
