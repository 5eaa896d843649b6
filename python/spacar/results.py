"""Results of an analysis block as NumPy arrays over the output times, with lookup by node and
element numbers (``res.node(8).x``, ``res.deformation(2, 2)``)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError


@dataclass(frozen=True)
class NodeResults:
    """Coordinates of one node over time: arrays of shape (nt, components)."""

    node: int
    x: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray


@dataclass(frozen=True)
class ElementResults:
    """Deformations of one element over time: arrays of shape (nt, deformations)."""

    element: int
    e: np.ndarray
    ed: np.ndarray
    edd: np.ndarray
    sigma: np.ndarray


class Results:
    """Arrays over the output times of one block.

    ``t`` (nt,), ``x``, ``xd``, ``xdd`` (nt, nx) for all nodal coordinates in ascending
    (node, component) order, ``e``, ``ed``, ``edd``, ``sigma`` (nt, ne) for all deformations in
    ascending (element, deformation) order; ``coordinate_labels`` and ``deformation_labels``
    give the (node, component) and (element, deformation) of each column.
    """

    def __init__(self, arrays: dict, coordinate_labels, deformation_labels, stats: dict):
        self.t = arrays["t"]
        self.x, self.xd, self.xdd = arrays["x"], arrays["xd"], arrays["xdd"]
        self.e, self.ed, self.edd, self.sigma = arrays["e"], arrays["ed"], arrays["edd"], arrays["sigma"]
        self.reaction = arrays["reaction"]  # (nt, nx): loads of supports and drivers (FORCEMODE ≥ 1)
        self.linearizations = []  # one spacar.Linearization per output time (LINE or LINEAR ≥ 1)
        self.coordinate_labels = [tuple(lbl) for lbl in coordinate_labels]
        self.deformation_labels = [tuple(lbl) for lbl in deformation_labels]
        self.stats = stats
        self._coord = {lbl: i for i, lbl in enumerate(self.coordinate_labels)}
        self._def = {lbl: i for i, lbl in enumerate(self.deformation_labels)}

    def _columns(self, table, number, what):
        cols = [i for (n, _), i in table.items() if n == number]
        if not cols:
            raise InputError(f"there is no {what} {number} in the results")
        return cols

    def node(self, n: int) -> NodeResults:
        cols = self._columns(self._coord, n, "node")
        return NodeResults(n, self.x[:, cols], self.xd[:, cols], self.xdd[:, cols])

    def element(self, e: int) -> ElementResults:
        cols = self._columns(self._def, e, "element")
        return ElementResults(e, self.e[:, cols], self.ed[:, cols], self.edd[:, cols], self.sigma[:, cols])

    def coordinate_index(self, n: int, i: int) -> int:
        try:
            return self._coord[(n, i)]
        except KeyError:
            raise InputError(f"node {n} has no component {i}") from None

    def deformation_index(self, e: int, i: int) -> int:
        try:
            return self._def[(e, i)]
        except KeyError:
            raise InputError(f"element {e} has no deformation {i}") from None

    def coordinate(self, n: int, i: int) -> np.ndarray:
        """Values of node n component i over time."""
        return self.x[:, self.coordinate_index(n, i)]

    def deformation(self, e: int, i: int) -> np.ndarray:
        """Values of element e deformation i over time."""
        return self.e[:, self.deformation_index(e, i)]

    def __len__(self):
        return len(self.t)

    def __repr__(self):
        if len(self.t) == 0:
            return (f"<spacar.Results: no output times, {self.x.shape[1]} coordinates, "
                    f"{self.e.shape[1]} deformations>")
        return (f"<spacar.Results: {len(self.t)} output times from t = {self.t[0]:g} to {self.t[-1]:g}, "
                f"{self.x.shape[1]} coordinates, {self.e.shape[1]} deformations>")
