"""The static equilibrium of a planar flexure model in exudyn, on spacar's coordinates: the
cross-check of :func:`spacar.static` with an independent, geometrically exact beam theory::

    from spacar.compare import exudyn_static
    peer = exudyn_static.solve(model, subdivide=4)   # the model as built, before spacar.static
    peer.x                                           # spacar's coordinate order
    peer.node(21)                                    # one node's coordinates

Each PLBEAM / PLBEAMNL becomes ``subdivide`` exudyn ``ObjectBeamGeometricallyExact2D`` elements
(Simo–Reissner beams with exact kinematics; spacar's beams are co-rotational Euler–Bernoulli
elements, so the two agree as both meshes are refined). The beam's elastic data come from its
ESTIFF (EA, EI) for released (RLSE) or DYNE deformations. A rigid bending (a rigid body) gets
``rigid`` times the model's largest EI; a rigid elongation the largest EA, at least 1e4 EI/l² of
the shortest beam (exudyn's Newton diverges on fine meshes with much stiffer penalties). Shear
is made ``shear`` times stiffer than the axial stiffness, so that exudyn's beams behave as
Euler–Bernoulli ones.

A pair of an XY node and a BETA node joined by beams is one exudyn rigid-body node; an XY node
shared with another BETA node is a pin (its positions are tied). FIX of XY or BETA coordinates
become coordinate constraints; FORCE on XY and BETA nodes dead loads. The solve is exudyn's
``SolveStatic`` in ``steps`` load steps with its full Newton. Anything else (other elements,
inputs, prescribed deformations, gravity) raises :class:`spacar.compare.UnsupportedModelError`.
"""
from __future__ import annotations

import time as _time

import numpy as np

try:
    import exudyn as exu
    from exudyn.itemInterface import (
        CoordinateConstraint,
        Force,
        MarkerNodeCoordinate,
        MarkerNodeRigid,
        NodePointGround,
        NodeRigidBody2D,
        ObjectBeamGeometricallyExact2D,
        Torque,
    )
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("spacar.compare.exudyn_static needs exudyn: pip install 'spacar[compare]' (from a clone of spacar: pip install '.[compare]')") from exc

from ._topology import UnsupportedModelError

BEAMS = ("PLBEAM", "PLBEAMNL")


class StaticResults:
    """exudyn's equilibrium on spacar's coordinates: ``x`` (the model's coordinates in the
    order of ``labels``, (node, component) 1-based), ``node(n)``, ``stats`` (wall time of the
    solve, exudyn's element and coordinate counts)."""

    def __init__(self, x, labels, stats):
        self.x, self.labels, self.stats = x, labels, stats

    def node(self, n):
        return np.array([v for (m, _), v in zip(self.labels, self.x) if m == n])


def _beam_data(model):
    """The beams: (element id, p, rp, q, rq, l0, EA, EI) with rigid deformations flagged by None."""
    beams = []
    for e, el in sorted(model.elements.items()):
        if el.type_name not in BEAMS:
            raise UnsupportedModelError(f"element {e} ({el.type_name}): exudyn_static converts PLBEAM and PLBEAMNL only")
        if any(el.e_given):
            raise UnsupportedModelError(f"element {e}: prescribed initial deformations are not converted")
        elastic = [c.name in ("released", "dynamic") for c in el.cls]
        if any(v != 0 for v in list(el.estiff)[2:]):
            raise UnsupportedModelError(f"element {e}: the shear stiffness kGA of a Timoshenko beam is not converted "
                                        "(the peer's beam here takes its own shear stiffness)")
        stiff = list(el.estiff) + [0.0] * (2 - len(el.estiff))
        EA = stiff[0] if elastic[0] else None
        EI = stiff[1] if elastic[1] or elastic[2] else None
        if elastic[1] != elastic[2]:
            raise UnsupportedModelError(f"element {e}: one bending deformation elastic and the other rigid")
        beams.append((e, *el.nodes, EA, EI))
    if not beams:
        raise UnsupportedModelError("the model has no beams")
    return beams


def _check_model(model):
    if np.any(np.asarray(model.core.gravity, dtype=float)):
        raise UnsupportedModelError("GRAVITY is not converted (no masses in a static flexure model)")
    for n, node in model.nodes.items():
        if any(c.name == "input" for c in node.cls):
            raise UnsupportedModelError(f"node {n}: INPUTX coordinates are not converted")


def solve(model, steps: int = 10, subdivide: int = 4, rigid: float = 1e5, shear: float = 1e2,
          tolerance: float = 1e-7) -> StaticResults:
    """The equilibrium of ``model`` under its FORCE loads, by exudyn's SolveStatic on
    geometrically exact beams; the model's current coordinates are its stress-free reference."""
    _check_model(model)
    beams = _beam_data(model)
    nodes = model.nodes
    pos = {n: np.asarray(node.x, dtype=float) for n, node in nodes.items()}
    EIs = [b[6] for b in beams if b[6] is not None]
    if not EIs:
        raise UnsupportedModelError("no beam bends elastically: nothing for a static solve to find")
    # A rigid elongation: the stiffest elastic one, at least 1e4 EI/l² of the shortest beam (an
    # axially rigid mesh); stiffer ones make exudyn's Newton diverge on fine meshes.
    shortest = min(np.linalg.norm(pos[b[3]] - pos[b[1]]) for b in beams)
    EA_rigid = max([b[5] for b in beams if b[5] is not None] + [1e4 * max(EIs) / shortest**2])
    EI_rigid = rigid * max(EIs)

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    rigid_node = {}      # (XY node, BETA node) -> exudyn node

    def node_of(p, rp):
        if (p, rp) not in rigid_node:
            rigid_node[(p, rp)] = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*pos[p], 0.0],
                                                              initialCoordinates=[0.0, 0.0, 0.0]))
        return rigid_node[(p, rp)]

    n_elements = 0
    for e, p, rp, q, rq, EA, EI in beams:
        a, b = pos[p], pos[q]
        length = float(np.linalg.norm(b - a))
        EA_e = EA if EA is not None else EA_rigid
        EI_e = EI if EI is not None else EI_rigid
        chain = [node_of(p, rp)]
        for k in range(1, subdivide):
            c = a + (b - a) * k / subdivide
            chain.append(mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*c, 0.0], initialCoordinates=[0.0, 0.0, 0.0])))
        chain.append(node_of(q, rq))
        for n0, n1 in zip(chain[:-1], chain[1:]):
            mbs.AddObject(ObjectBeamGeometricallyExact2D(
                nodeNumbers=[n0, n1], length=length / subdivide, massPerLength=0.0,
                bendingStiffness=EI_e, axialStiffness=EA_e, shearStiffness=shear * EA_e,
                includeReferenceRotations=False))
            n_elements += 1

    ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))

    def coordinate(node, i):
        return mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=i))

    # Pins: an XY node in several pairs ties their positions; a BETA node in several pairs (a
    # rigid body's ends) their rotations. Supports: FIX on the first pair of the node.
    first = {}
    for (p, rp), node in rigid_node.items():
        for key, rot in ((p, False), (rp, True)):
            if key in first:
                for i in ((2,) if rot else (0, 1)):
                    mbs.AddObject(CoordinateConstraint(markerNumbers=[coordinate(first[key], i), coordinate(node, i)]))
            else:
                first[key] = node
    for n, node in nodes.items():
        if n not in first:
            continue
        components = (2,) if node.kind.name == "BETA" else (0, 1)
        for i, c in zip(components, node.cls):
            if c.name == "fixed":
                mbs.AddObject(CoordinateConstraint(markerNumbers=[ground, coordinate(first[n], i)]))
        force = np.asarray(node.force, dtype=float)
        if np.any(force):
            marker = mbs.AddMarker(MarkerNodeRigid(nodeNumber=first[n]))
            if node.kind.name == "BETA":
                mbs.AddLoad(Torque(markerNumber=marker, loadVector=[0.0, 0.0, float(force[0])]))
            else:
                mbs.AddLoad(Force(markerNumber=marker, loadVector=[float(force[0]), float(force[1]), 0.0]))
    mbs.Assemble()

    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.solution.sensors.active = False
    settings.staticSolver.numberOfLoadSteps = int(steps)
    settings.staticSolver.newton.relativeTolerance = tolerance
    settings.staticSolver.newton.absoluteTolerance = tolerance * 1e-3
    settings.staticSolver.newton.useModifiedNewton = False
    settings.staticSolver.verboseMode = 0
    settings.show.statistics = False
    settings.show.computationTime = False
    settings.show.globalTimers = False
    if len(mbs.systemData.GetODE2Coordinates()) > 200:
        settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    t0 = _time.perf_counter()
    ok = mbs.SolveStatic(settings)
    wall = _time.perf_counter() - t0
    if not ok:
        raise RuntimeError("exudyn's SolveStatic did not converge")

    labels, x = [], []
    for n in sorted(first):
        state = mbs.GetNodeOutput(first[n], exu.OutputVariableType.Coordinates)
        if nodes[n].kind.name == "BETA":
            labels.append((n, 1))
            x.append(float(nodes[n].x[0]) + state[2])
        else:
            labels += [(n, 1), (n, 2)]
            x += list(pos[n] + np.asarray(state[:2]))
    stats = {"wall": wall, "elements": n_elements, "coordinates": len(mbs.systemData.GetODE2Coordinates())}
    return StaticResults(np.array(x), labels, stats)
