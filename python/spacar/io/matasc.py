"""MATASC files (manual §5.6 ``MATASC 1``; formulation.md §9.4; docs/matasc.md).

At every output time the state goes to ASCII files named after the input file, one line per
output time, written and flushed as the run proceeds (an aborted run keeps every line computed
so far). The files load with MATLAB ``load`` and ``numpy.loadtxt`` (``%`` lines are comments):

================  ==========================================================  ==================
file              columns after t                                             written when
================  ==========================================================  ==================
<stem>_x.asc      all nodal coordinates, ascending (node, component): x(n,i)  MATASC 1
<stem>_xd.asc     their velocities xd(n,i)                                    MATASC 1
<stem>_xdd.asc    their accelerations xdd(n,i)                                MATASC 1
<stem>_e.asc      all deformations, ascending (element, deformation): e(k,i)  MATASC 1
<stem>_ed.asc     their rates ed(k,i)                                         MATASC 1
<stem>_edd.asc    their second rates edd(k,i)                                 MATASC 1
<stem>_rx.asc     reactions on the fixed and input coordinates: r(n,i)        FORCEMODE ≥ 1
<stem>_sig.asc    stresses of all deformations: s(k,i)                        FORCEMODE 2
<stem>_lin.asc    nz, nk, M0, C0, D0, K0, N0, G0 (column-major), K_k, AK0,    LINE or LINEAR ≥ 1
                  BK0, r0
<stem>_eig.asc    eigenvalues (Re, Im pairs) of the linearized equations      LINE or LINEAR ≥ 1
<stem>_buck.asc   buckling multipliers, sorted by absolute value              LINEAR 2
================  ==========================================================  ==================

Numbers are written ``%.15E``, one space apart; column 1 is t. The files are created (emptied)
at the first MATASC 1 block of a model and appended to by later blocks, so a block boundary
time appears twice. An existing file is overwritten, as SPACAR does, but never through a
symbolic link (spacar.io.files).

Each output time is one transaction over all the files: its lines are written whole, and if
any write fails (a full disk, a file size limit) every file is cut back to where it was before
that output time, so the files always hold the same output times in whole lines, and the run
stops with a :class:`spacar.SpacarError` naming the file.
"""
from __future__ import annotations

import os
import threading
from pathlib import Path

import numpy as np

from ..errors import SpacarError
from ..results import QUANTITIES
from .files import open_output, reason, write_all

FMT = "%.15E"
# Held while an output time is written: `spacar run` takes it before it exits on Ctrl-C, so the
# files it leaves hold whole output times.
WRITING = threading.RLock()

# file suffix: the quantity it holds (spacar.results.QUANTITIES: attribute, coordinates or
# deformations, column label prefix) and the description in its header
STATE_FILES = {
    "x": ("x", "nodal coordinates"),
    "xd": ("xd", "velocities of the nodal coordinates"),
    "xdd": ("xdd", "accelerations of the nodal coordinates"),
    "e": ("e", "deformations"),
    "ed": ("ed", "deformation rates"),
    "edd": ("edd", "deformation second rates"),
    "rx": ("reaction", "reactions on the fixed and input coordinates (FORCEMODE >= 1)"),
    "sig": ("sigma", "generalized stresses of all deformations (FORCEMODE 2)"),
}


def default_stem(model) -> str:
    """The stem of the output files of a model: ``model.output_stem`` if set; else the input
    file name without extension (with its directory, so the files go next to the input);
    ``spacar`` (in the current directory) for models built in Python or read from a string."""
    if getattr(model, "output_stem", None):
        return os.fspath(model.output_stem)
    source = getattr(model, "source", None)
    if source and not (source.startswith("<") and source.endswith(">")):
        return os.fspath(Path(source).with_suffix(""))
    return "spacar"


def format_line(values) -> str:
    return " ".join(FMT % v for v in values) + "\n"


class MatascWriter:
    """Writes one block's output times to the MATASC files; use as the ``on_output`` callback
    of a run (``writer.write(k, state)``), and call :meth:`close` at the end of the block.

    ``created`` ({path: column header}) is kept by the model between blocks: a file in it is
    appended to; any other file is created with its header.
    """

    def __init__(self, stem, *, source, jobid, version, coordinate_labels, deformation_labels,
                 coordinate_classes, forcemode: int, created: dict):
        self.stem = os.fspath(stem)
        self.source = source
        self.jobid = jobid
        self.version = version
        self.coordinate_labels = [tuple(c) for c in coordinate_labels]
        self.deformation_labels = [tuple(c) for c in deformation_labels]
        self.created = created
        supported = [i for i, c in enumerate(coordinate_classes) if c in ("fixed", "input")]
        self._files = {}      # suffix: file descriptor
        self._lin_files = {}  # _lin, _eig, _buck: opened at the first linearization
        self._columns = {}
        self._marks = {}      # suffix: the file's size before the current output time
        self._last_t = None   # the last output time written completely
        self._held = False    # WRITING held between write and write_linearization
        try:
            self._open_state_files(supported, forcemode)
        except BaseException:
            self.close()
            raise

    def _open_state_files(self, supported, forcemode):
        for suffix, (quantity, text) in STATE_FILES.items():
            key, over, prefix, _ = QUANTITIES[quantity]
            if suffix == "rx" and forcemode < 1 or suffix == "sig" and forcemode < 2:
                continue
            labels = self.coordinate_labels if over == "coordinate" else self.deformation_labels
            cols = supported if suffix == "rx" else list(range(len(labels)))
            header = ["t"] + [f"{prefix}({labels[i][0]},{labels[i][1]})" for i in cols]
            self._columns[suffix] = (key, np.asarray(cols, dtype=int))
            self._files[suffix] = self._open(suffix, text, header)

    def path(self, suffix: str) -> str:
        return f"{self.stem}_{suffix}.asc"

    @property
    def paths(self) -> list:
        return [self.path(suffix) for suffix in self._files]

    def _open(self, suffix, text, header, extra=()):
        path = self.path(suffix)
        columns = "% columns: " + " ".join(header) + "\n"
        key = os.path.abspath(path)
        lines = []
        if key in self.created:
            append = True
            if self.created[key] != columns:  # e.g. other supports in this block
                lines.append(columns)
        else:
            append = False
            try:
                Path(path).parent.mkdir(parents=True, exist_ok=True)
            except OSError as err:
                raise SpacarError(f"{path}: cannot create the directory of the MATASC file ({reason(err)})") from None
            lines.append(f"% spacar {self.version} MATASC file {Path(path).name}: {text}\n")
            lines.append(f"% input: {self.source or '(model built in Python)'}\n")
            lines.append(f"% JOBID: {'none' if self.jobid is None else self.jobid}\n")
            lines.extend(f"% {line}\n" for line in extra)
            lines.append(columns)
        fd = open_output(path, append=append)
        try:
            write_all(fd, "".join(lines).encode("ascii", "replace"))
        except OSError as err:
            os.close(fd)
            raise SpacarError(f"{path}: cannot write the MATASC file ({reason(err)})") from None
        self.created[key] = columns
        return fd

    def _commit(self, files: dict, lines: dict) -> None:
        """Write one output time's lines ({suffix: text}); on a failure cut every file back to
        its size before this output time and raise a SpacarError naming the file."""
        with WRITING:
            self._write_lines(files, lines)

    def _write_lines(self, files: dict, lines: dict) -> None:
        for suffix, text in lines.items():
            try:
                write_all(files[suffix], text.encode("ascii"))
            except OSError as err:
                self._roll_back()
                done = "none" if self._last_t is None else f"those up to t = {self._last_t:g}"
                raise SpacarError(f"{self.path(suffix)}: cannot write the MATASC file ({reason(err)}); the "
                                  f"MATASC files {self.stem}_*.asc hold whole lines of the same output times: "
                                  f"{done}") from None

    def _roll_back(self) -> None:
        with WRITING:
            self._cut_back()

    def _cut_back(self) -> None:
        for suffix, fd in (*self._files.items(), *self._lin_files.items()):
            if suffix in self._marks:
                try:
                    os.ftruncate(fd, self._marks[suffix])
                except OSError:  # nothing better to do: the write error is reported
                    pass

    def _mark(self, files: dict) -> None:
        for suffix, fd in files.items():
            self._marks[suffix] = os.fstat(fd).st_size

    def write(self, k: int, state: dict) -> None:
        """One output time: a line in every state file (the linearization files are written by
        write_linearization, in the same transaction)."""
        t = float(state["t"])
        self._marks = {}
        self._mark(self._files)
        self._mark(self._lin_files)
        lines = {}
        for suffix in self._files:
            key, cols = self._columns[suffix]
            values = np.asarray(state[key], dtype=float)[cols]
            lines[suffix] = format_line(np.concatenate(([t], values)))
        if "linearization" in state:
            # The linearization's lines follow (write_linearization): the output time is one
            # transaction, so WRITING stays held until they are written.
            WRITING.acquire()
            self._held = True
        self._commit(self._files, lines)
        if "linearization" not in state:
            self._last_t = t

    def write_linearization(self, lin, linear_mode) -> None:
        """``_lin``, ``_eig`` (and ``_buck`` for LINEAR 2): a line for the output time just
        written by :meth:`write` (the same transaction); the files are opened at the first
        linearization."""
        try:
            self._write_linearization(lin, linear_mode)
        finally:
            self._release()

    def _release(self) -> None:
        if self._held:
            self._held = False
            WRITING.release()

    def _write_linearization(self, lin, linear_mode) -> None:
        nz, nk = len(lin.z_labels), len(lin.y_labels)
        if "lin" not in self._lin_files:
            try:
                self._open_linearization_files(lin, linear_mode)
            except BaseException:
                self._roll_back()  # this output time's state lines
                raise
            self._mark(self._lin_files)  # (after their headers)
        files = self._lin_files
        lines = {}
        row = [lin.t, nz, nk]
        for name in ("M0", "C0", "D0", "K0", "N0", "G0", "Kk", "AK0", "BK0"):
            row.extend(np.asarray(getattr(lin, name)).ravel(order="F"))
        row.extend(np.asarray(lin.r0).ravel())
        lines["lin"] = format_line(row)
        lam = lin.eigenvalues()
        lines["eig"] = format_line([lin.t] + [v for z_ in lam for v in (z_.real, z_.imag)])
        if "buck" in files:
            mu = np.real(lin.buckling_factors())
            pad = np.full(nz, np.nan)
            pad[: min(len(mu), nz)] = mu[:nz]
            lines["buck"] = format_line([lin.t, *pad])
        self._commit(files, lines)
        self._last_t = float(lin.t)

    def _open_linearization_files(self, lin, linear_mode) -> None:
        nz, nk = len(lin.z_labels), len(lin.y_labels)
        z = " ".join(f"{k}({a},{b})" for k, a, b in lin.z_labels)
        y = " ".join(f"{k}({a},{b})" for k, a, b in lin.y_labels)
        n_eig = 2 * nz + nk
        self._lin_files["lin"] = self._open(
            "lin", "linearized equations",
            ["t", "nz", "nk", "M0", "C0", "D0", "K0", "N0", "G0", "K_k", "AK0", "BK0", "r0"],
            extra=[f"z: {z}", f"kinematic coordinates: {y or 'none'}",
                   "M0..G0 nz x nz, K_k nz x nk, AK0 nk x nz, BK0 nk x (nz + nk), column-major"])
        self._lin_files["eig"] = self._open(
            "eig", "eigenvalues of the linearized equations",
            ["t"] + [f"{p}{i}" for i in range(1, n_eig + 1) for p in ("re", "im")],
            extra=[f"z: {z}", "eigenvalues of the first-order system, sorted by |Im|, then Re"])
        if linear_mode == 2:
            self._lin_files["buck"] = self._open(
                "buck", "buckling multipliers", ["t"] + [f"mu{i}" for i in range(1, nz + 1)],
                extra=[f"z: {z}", "real parts, sorted by absolute value; NaN pads missing (infinite) multipliers"])

    def close(self) -> None:
        self._release()
        for fd in (*self._files.values(), *self._lin_files.values()):
            os.close(fd)
        self._files = {}
        self._lin_files = {}
