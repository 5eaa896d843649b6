"""Checks of a model before an analysis (``spacar check``): nodes and elements by type,
coordinates and deformations per class, degrees of freedom, and the diagnosis of the constraint
block — which rigid deformations are redundant and could be released, which coordinates are
undetermined (formulation.md §2.3) — and the release of the redundant ones
(``spacar check --release``, :func:`release_overconstraints`)."""
from __future__ import annotations

import time
from collections import Counter
from dataclasses import dataclass, field

from . import _core
from ._util import seconds_or_none, show, time_limited
from .errors import InputError, KinematicsError
from .model import Model

COORD_CLASSES = ("fixed", "input", "dynamic", "calculable")
DEF_CLASSES = ("fixed", "released", "input", "dynamic", "linearization", "nonholonomic", "kinematic")


@dataclass
class Summary:
    nodes: Counter
    elements: Counter
    coordinates: Counter
    deformations: Counter

    @property
    def n_coordinates(self) -> int:
        return sum(self.coordinates.values())

    @property
    def n_deformations(self) -> int:
        return sum(self.deformations.values())

    @property
    def degrees_of_freedom(self) -> int:
        return self.coordinates["dynamic"] + self.deformations["dynamic"]

    def lines(self):
        def fmt(counter, order=None):
            keys = order or sorted(counter)
            parts = ", ".join(f"{counter[k]} {k}" for k in keys if counter[k])
            return f"{sum(counter.values())} ({parts})" if parts else "0"

        yield f"nodes: {fmt(self.nodes)}"
        yield f"elements: {fmt(self.elements)}"
        yield f"nodal coordinates: {fmt(self.coordinates, COORD_CLASSES)}"
        yield f"deformations: {fmt(self.deformations, DEF_CLASSES)}"
        yield f"degrees of freedom: {self.degrees_of_freedom}"

    def __str__(self):
        return "\n".join(self.lines())


@dataclass
class Diagnosis:
    """Solvability of the position constraints at the given geometry."""

    n_constraints: int
    n_calculable: int
    rank: int
    redundant: list      # (element, deformation): release these (RLSE) to remove the redundancy
    undetermined: list   # (node, component): fix them, make them DOFs or add elements
    text: str
    # (node, component) of DYNX/INPUTX coordinates that the constraints determine: over-constrained,
    # making one of them calculable again removes a redundancy (e.g. a DYNX added too many)
    determined: list = field(default_factory=list)

    @property
    def detailed(self) -> bool:
        """False for a constraint block too large to diagnose (rank -1: counts only)."""
        return self.rank >= 0

    @property
    def ok(self) -> bool:
        return (self.detailed and not self.redundant and not self.undetermined
                and self.n_constraints == self.n_calculable)


@dataclass
class Check:
    summary: Summary
    diagnosis: Diagnosis
    assembly: str = ""  # why the model cannot be assembled (lengths that cannot close a loop), or ""

    @property
    def ok(self) -> bool:
        """Nothing to report: a model with elements whose constraints determine its calculable
        coordinates and can be met (``spacar check`` exits 1 otherwise)."""
        return self.diagnosis.ok and sum(self.summary.elements.values()) > 0 and not self.assembly

    def __str__(self):
        if self.ok:
            verdict = "the constraints determine the calculable coordinates"
        else:
            verdict = "problems:" if self.diagnosis.detailed else "not diagnosed:"
        text = f"{self.summary}\nconstraints: {verdict}\n{self.diagnosis.text}"
        return text + (f"\nassembly: {self.assembly}" if self.assembly else "")


def _latest_prescribed(model, determined) -> str:
    """Of the DYNX/INPUTX coordinates the constraints determine, the one whose line came last
    (the likeliest slip: a line just added), with where it was given; "" if none is known."""
    records = getattr(model, "_prescribed", {})
    known = [r for n, c in determined for r in (records.get((n, c)), records.get((n, 0))) if r is not None]
    if not known:
        return ""
    _, line, origin = max(known)
    return f"\n  the latest line that prescribed one of them: {line}" + (f" ({origin})" if origin else "") + \
        "; removing it removes the redundancy"


def check(model, time_limit=None, *, release_dynamic: bool = False) -> Check:
    """Summary and constraint diagnosis of ``model`` at its given geometry (no assembly).
    ``time_limit``: wall-clock seconds the set-up and the diagnosis may take (None: no limit);
    beyond it :class:`spacar.TimeLimitError` (the diagnosis's decomposition itself, of at most
    1500 rows, is not interrupted: it starts only within the limit). ``release_dynamic``: the
    redundant deformations named among the degrees of freedom (DYNE) where they can be, the
    fixed and input ones kept (spacar.light's automatic release), rather than among the fixed."""
    if not isinstance(model, Model):
        raise InputError(f"check: model must be a spacar.Model, got {show(model)}")
    limit = seconds_or_none(time_limit, "time_limit") or 0.0
    started = time.monotonic()
    if not model.nodes and not model.elements:
        why = " (no input block ended with END)" if getattr(model, "source", None) and not model.blocks else ""
        return Check(summary(model), Diagnosis(0, 0, 0, [], [], f"  the model is empty{why}"))
    copy = model.copy()
    copy.prepare()
    sim = _core.Simulation(copy.core, time_limit=limit, time_spent=time.monotonic() - started)
    d = sim.diagnose(time_limit=limit, time_spent=time.monotonic() - started, release_dynamic=release_dynamic)
    diagnosis = Diagnosis(d["n_constraints"], d["n_calculable"], d["rank"], list(d["redundant"]),
                          list(d["undetermined"]), d["text"] + _latest_prescribed(model, d["determined"]),
                          list(d["determined"]))
    assembly = ""
    if diagnosis.ok:  # the constraints are independent: can they be met? (lengths that close no loop)
        left = None if not limit else max(limit - (time.monotonic() - started), 1e-9)  # one limit for all of check
        try:
            with time_limited(left, "in the assembly"):
                sim.assemble()
        except KinematicsError as err:
            assembly = str(err)
    return Check(summary(model), diagnosis, assembly)


def release_overconstraints(model, time_limit=None) -> list:
    """Release (RLSE) the redundant rigid deformations that the constraint diagnosis names
    (``model.check().diagnosis.redundant``), as SPACAR Light's "autosolve" does: afterwards the
    constraints have full rank. Returns the released ``(element, deformation)`` pairs, empty
    if nothing is over-constrained. The released deformations carry no stress (or that of their
    ESTIFF, if given). Undetermined coordinates are not touched (the diagnosis still names
    them). Raises InputError, changing nothing, when a redundant deformation cannot be released
    (an input or degree-of-freedom deformation, or one of the automatic L2MIN1 elements of a
    LAMBDA node: fix the model by hand there) or the constraint block is too large to diagnose.
    ``time_limit``: as for :func:`check`."""
    diagnosis = check(model, time_limit=time_limit).diagnosis
    if not diagnosis.detailed:
        raise InputError("the constraint block is too large for the diagnosis: no over-constraints released")
    elements = model.elements
    refused = []
    for e, i in diagnosis.redundant:
        el = elements.get(e)
        if el is None or el.cls[i - 1].name != "fixed":
            what = "an automatic element" if el is None else f"{el.cls[i - 1].name}, not fixed"
            refused.append(f"element {e} deformation {i} ({what})")
    if refused:
        raise InputError("cannot release the redundant constraints " + ", ".join(refused) +
                         ": only fixed deformations of the input can be released (RLSE)")
    for e, i in diagnosis.redundant:
        model.rlse(e, i)
    return list(diagnosis.redundant)


def summary(model) -> Summary:
    """Counts for ``model`` as it will be analysed: the automatic L2MIN1 elements of the LAMBDA
    nodes are included (they are created at the first END). An empty model (e.g. an input of
    comments only) has all counts zero."""
    if not isinstance(model, Model):
        raise InputError(f"summary: model must be a spacar.Model, got {show(model)}")
    core = model.core.copy()
    if not core.nodes and not core.elements:
        return Summary(Counter(), Counter(), Counter(), Counter())
    core.prepare()
    nodes = Counter(str(n.kind.name) for n in core.nodes.values())
    elements = Counter(el.type_name for el in core.elements.values())
    coords = Counter(c.name for n in core.nodes.values() for c in n.cls)
    defs = Counter(c.name for el in core.elements.values() for c in el.cls)
    return Summary(nodes, elements, coords, defs)


__all__ = ["Summary", "Diagnosis", "Check", "summary", "check", "release_overconstraints"]
