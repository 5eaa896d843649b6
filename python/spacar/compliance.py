"""Static compliance at a node (docs/statics.md, "Compliance")::

    res = spacar.static(model)                     # the equilibrium (skip for an unloaded model)
    C = spacar.compliance(model, 21, rotation=22)  # planar: 3 x 3 in (x, y, β) per (Fx, Fy, M)
    K = np.linalg.inv(C)                           # the stiffness at the node

The compliance is that of the tangent stiffness of the static solve (K0 + G0 at the model's
current state under the block's full loads) seen through the transfer function of the node:

    C = T K⁻¹ Tᵀ,   T = DF_node (∂x_node/∂q)

so C_ij is the displacement i of the node per unit load j on it (a small load added to the
block's loads). For a LAMBDA node the rows of T are the small rotation vector in global axes,
δθ = 2 E(λ) δλ (docs/formulation.md §2): the rotations are compliant to moments in global axes.
K is never formed: each column of C is one solve of the sparse saddle-point system of the nodal
coordinates (docs/formulation.md §10), so the cost grows linearly with the size of the model.
"""
from __future__ import annotations

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError

# The node kinds whose displacements the compliance gives (a LAMBDA node: its rotation vector).
_SIZE = {"XY": 2, "BETA": 1, "XYZ": 3}


def _node(nodes: dict, n, what: str) -> int:
    """Node n, checked to be a node of the model with a displacement."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or int(n) not in nodes:
        raise InputError(f"{what} {show(n)} is not a node of the model")
    if nodes[int(n)].kind.name not in (*_SIZE, "LAMBDA"):
        raise InputError(f"{what} {int(n)} has no coordinates used by an element")
    return int(n)


def compliance(model, node, rotation=None, *, results=None, k: int = -1, time_limit=None) -> np.ndarray:
    """The static compliance at ``node`` at the model's current state (an equilibrium: after
    :func:`spacar.static`, which leaves the model there, or an unloaded model), or at row ``k``
    of ``results`` of :func:`spacar.static` of this model (its load factor λ = ``results.t[k]``
    and its degrees of freedom; e.g. the drive stiffness along a load path; loads reached from
    an unloaded start, inputs not moving). ``model`` may also be those results themselves,
    ``compliance(res, node, k=...)``: they keep the model they were solved for (not through a
    pickle: loaded results need the model passed).

    ``node``: a position node (XY: rows x, y; XYZ: x, y, z) or a rotation node alone (BETA: β;
    LAMBDA: the rotation vector in global axes); ``rotation``: the BETA or LAMBDA node of the
    same point, appended (planar 3 × 3 in x, y, β; spatial 6 × 6 in x, y, z, θx, θy, θz).
    Returns C (m × m): the displacements and rotations per unit force and moment at the node,
    in global axes. The tangent includes the geometric stiffness of the current stresses and
    loads (stress stiffening, a compressive load's softening). A direction that is fixed (a
    support) has zero compliance.

    Raises :class:`spacar.StaticError` when the tangent stiffness is singular (a mechanism: a
    degree of freedom without stiffness), naming the direction. ``time_limit``: wall-clock
    seconds it may take (:class:`spacar.TimeLimitError` beyond)."""
    from .model import Model
    from .results import Results

    if isinstance(model, Results):
        if results is not None:
            raise InputError("give the static results once: compliance(results, node) or compliance(model, node, results=...)")
        results = model
        model = getattr(results, "_static_model", None)
        if callable(model):  # a StaticSolver's load case: its model made when first needed
            model = results._static_model = model()
        if model is None:
            raise InputError("these results do not carry their model (only spacar.static's do, and not through a "
                             "pickle): call compliance(model, node, results=res)")
    if not isinstance(model, Model):
        raise InputError(f"compliance needs a spacar.Model (at its equilibrium) or spacar.static's results, got {show(model)}")
    nodes = model.nodes
    chosen = [_node(nodes, node, "node")]
    if rotation is not None:
        is_number = isinstance(rotation, (int, np.integer)) and not isinstance(rotation, bool)
        if not is_number or int(rotation) not in nodes or nodes[int(rotation)].kind.name not in ("BETA", "LAMBDA"):
            raise InputError(f"rotation {show(rotation)} must be a BETA or LAMBDA node of the model")
        chosen.append(int(rotation))
    if results is None:
        with time_limited(time_limit, "in the compliance"):
            return np.asarray(_core.static_compliance(model.core, chosen))
    if getattr(results, "stats", {}).get("analysis") != "static":
        raise InputError("results must come from spacar.static (the rows are equilibria at load factors)")
    k = range(len(results.t))[k]
    with time_limited(time_limit, "in the compliance"):
        return np.asarray(_core.static_compliance(model.core, chosen, float(results.t[k]),
                                                  np.asarray(results.x[k], dtype=float),
                                                  np.asarray(results.e[k], dtype=float)))


def support_stiffness(model, node, components=None, *, time_limit=None) -> np.ndarray:
    """The stiffness of a support or drive: the response of the reactions on the prescribed
    (FIX or INPUTX) coordinates ``components`` of ``node`` (1-based; default: all of its
    prescribed ones) to a unit prescribed displacement of each, the rest of the model in
    equilibrium, at the model's current state: K_s = ∂r_p/∂x_p (m × m, e.g. a flexure's drive
    stiffness, or the stiffness of a guide in its supported directions).

    Computed exactly as the Schur complement of the tangent stiffness: on a copy of the model the
    coordinates become degrees of freedom (DYNX), the DYNE deformations that this makes
    redundant (named by the constraint diagnosis) become RLSE (their stiffness stays), as do rigid
    deformations it makes redundant (a stage of rigid beams closing a loop of its own: they stay
    rigid through the others; a warning names them), and K_s = C_pp⁻¹ with C_pp their compliance
    (:func:`compliance`). Position (XY, XYZ) and BETA
    nodes. ``time_limit``: wall-clock seconds it may take (:class:`spacar.TimeLimitError` beyond)."""
    from .model import Model

    if not isinstance(model, Model):
        raise InputError(f"support_stiffness needs a spacar.Model (at its equilibrium), got {show(model)}")
    nodes = model.nodes
    if isinstance(node, bool) or not isinstance(node, (int, np.integer)) or int(node) not in nodes:
        raise InputError(f"node {show(node)} is not a node of the model")
    n = int(node)
    if nodes[n].kind.name not in _SIZE:
        raise InputError(f"node {n} ({nodes[n].kind.name}): the support stiffness is for XY, XYZ and BETA nodes")
    classes = [c.name for c in nodes[n].cls]
    prescribed = [i + 1 for i, c in enumerate(classes) if c in ("fixed", "input")]
    if components is None:
        components = prescribed
    components = [int(i) for i in np.atleast_1d(components)]
    if not components or any(i not in prescribed for i in components):
        raise InputError(f"components {show(components)} must be prescribed (FIX, INPUTX) components of node {n}; "
                         f"its prescribed ones: {prescribed}")
    with time_limited(time_limit, "in the support stiffness"):
        return _support_stiffness(model, n, components)


def _support_stiffness(model, n, components):
    free = model.copy()
    free.dynx(n, *components)
    rigid = []
    for e, i in free.check().diagnosis.redundant:
        if free.elements[e].cls[i - 1].name != "dynamic":
            rigid.append((e, i))  # a rigid body (a stage of rigid beams) closes a loop of its own: redundant
        free.rlse(e, i)
    if rigid:
        import warnings

        names = ", ".join(f"deformation {i} of element {e}" for e, i in rigid)
        warnings.warn(f"support_stiffness: freeing node {n} components {components} made the rigid {names} redundant "
                      "(a rigid body's own loop); released to compute the stiffness (RLSE), which leaves the body rigid",
                      stacklevel=2)
    C = compliance(free, n)
    rows = [i - 1 for i in components]
    return np.linalg.inv(C[np.ix_(rows, rows)])
