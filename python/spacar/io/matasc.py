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
time appears twice.
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..results import QUANTITIES

FMT = "%.15E"

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
        self._files = {}
        self._lin_files = {}  # _lin, _eig, _buck: opened at the first linearization
        self._columns = {}
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
        return [fh.name for fh in self._files.values()]

    def _open(self, suffix, text, header, extra=()):
        path = self.path(suffix)
        columns = "% columns: " + " ".join(header) + "\n"
        key = os.path.abspath(path)
        if key in self.created:
            fh = open(path, "a", encoding="ascii")
            if self.created[key] != columns:  # e.g. other supports in this block
                fh.write(columns)
                self.created[key] = columns
        else:
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            fh = open(path, "w", encoding="ascii")
            fh.write(f"% spacar {self.version} MATASC file {Path(path).name}: {text}\n")
            fh.write(f"% input: {self.source or '(model built in Python)'}\n")
            fh.write(f"% JOBID: {'none' if self.jobid is None else self.jobid}\n")
            for line in extra:
                fh.write(f"% {line}\n")
            fh.write(columns)
            self.created[key] = columns
        fh.flush()
        return fh

    def write(self, k: int, state: dict) -> None:
        """One output time: a line in every state file, flushed (the linearization files are
        written by write_linearization)."""
        t = float(state["t"])
        for suffix, fh in self._files.items():
            key, cols = self._columns[suffix]
            values = np.asarray(state[key], dtype=float)[cols]
            fh.write(format_line(np.concatenate(([t], values))))
            fh.flush()

    def write_linearization(self, lin, linear_mode) -> None:
        """``_lin``, ``_eig`` (and ``_buck`` for LINEAR 2): a line for one output time, flushed;
        the files are opened at the first linearization."""
        nz, nk = len(lin.z_labels), len(lin.y_labels)
        if "lin" not in self._lin_files:
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
        files = self._lin_files
        row = [lin.t, nz, nk]
        for name in ("M0", "C0", "D0", "K0", "N0", "G0", "Kk", "AK0", "BK0"):
            row.extend(np.asarray(getattr(lin, name)).ravel(order="F"))
        row.extend(np.asarray(lin.r0).ravel())
        files["lin"].write(format_line(row))
        lam = lin.eigenvalues()
        files["eig"].write(format_line([lin.t] + [v for z_ in lam for v in (z_.real, z_.imag)]))
        if "buck" in files:
            mu = np.real(lin.buckling_factors())
            pad = np.full(nz, np.nan)
            pad[: min(len(mu), nz)] = mu[:nz]
            files["buck"].write(format_line([lin.t, *pad]))
        for fh in files.values():
            fh.flush()

    def close(self) -> None:
        for fh in (*self._files.values(), *self._lin_files.values()):
            fh.close()
        self._files = {}
        self._lin_files = {}
