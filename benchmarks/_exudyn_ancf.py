"""exudyn's side of the static elastica benchmark (benchmarks/statics.py): the cantilever of
length L and bending stiffness EI, clamped at x = 0 along x, under a dead tip load P along y,
as n ``ObjectANCFCable2D`` elements or n ``ObjectBeamGeometricallyExact2D`` elements, solved by
``SolveStatic``::

    import _exudyn_ancf as X
    case = X.build_ancf(64)                  # or X.build_ge(64); built and assembled
    out = X.solve(case, X.settings(steps=1))  # {"ok", "tip", "iterations", "steps", "wall"}

* ANCF cable (Bernoulli–Euler, cubic Hermite positions): n + 1 ``NodePoint2DSlope1`` nodes
  (position and slope vector r' = ∂r/∂x), clamped as in exudyn's own cantilever examples
  (``fixedConstraintsNode0=[1, 1, 0, 1]``): ``CoordinateConstraint`` on the first node's x, y
  and slope y (the slope's x component, the root's stretch, stays free; the load has no axial
  component there); the load a ``LoadForceVector`` on the last node's position. Reduced Gauss
  integration (``useReducedOrderIntegration=1``: order 7 for the axial, 3 for the bending work;
  the same tips to 1 %, a little faster).
* Geometrically exact beam (Simo–Reissner, linear interpolation): the model of
  ``spacar.compare.exudyn_static`` (n + 1 ``NodeRigidBody2D`` nodes, coordinate constraints on
  the root's x, y and rotation, a ``Force`` on the tip node) with one change: shear stiffness
  GA = EA instead of the converter's 100 EA. With 100 EA, full Newton from the straight beam
  diverges in one load step at every mesh and exudyn needs its adaptive load stepping (15–25
  steps, some 250 iterations; statics.py's probes); with GA = EA one step converges. The shear
  compliance this adds (Q/GA, GA ∝ n²) moves the tip by about 0.1 % of the discretization error.

Both: EA = ``ea_factor`` · EI / l² of an element (default 1e4, the converter's rule for an
axially rigid beam; l = L/n), so that the stretch, about P/EA, stays 1e-4/n² L and below the
discretization error (ANCF's h⁴ error meets it near n = 1000 at about 1e-10 L).

Settings (``settings``): the sparse solver (EigenSparse; statics.py also times the dense
EigenDense on small meshes, where it can be faster), full Newton, at most 50 iterations a
step, exudyn's adaptive load stepping from ``steps`` equal steps, no loads Jacobian (the loads
are dead), and convergence judged on the Newton increment (``newton.residualMode = 1``,
relative and absolute tolerance ``tolerance``): exudyn's default residual criterion is relative
to the residual after the first iteration (``adaptInitialResidual``), which the stiff axial
forces inflate by orders of magnitude, so it stops early with tips 1e-2 … 0.3 L off.
"""
from __future__ import annotations

import time

import numpy as np

import exudyn as exu
from exudyn.itemInterface import (
    CoordinateConstraint,
    Force,
    LoadForceVector,
    MarkerNodeCoordinate,
    MarkerNodePosition,
    MarkerNodeRigid,
    NodePoint2DSlope1,
    NodePointGround,
    NodeRigidBody2D,
    ObjectANCFCable2D,
    ObjectBeamGeometricallyExact2D,
)

EA_FACTOR = 1e4


def quiet():
    """No console output from exudyn (solver banners, failure reports)."""
    try:
        exu.config.printToConsole = False
    except AttributeError:  # pragma: no cover - older exudyn
        exu.SetWriteToConsole(False)


class Case:
    """An assembled exudyn model of the cantilever: ``mbs`` (its ``SC`` kept alive), the tip
    node, the element kind and data."""

    def __init__(self, SC, mbs, tip, kind, n, EA, GA=None):
        self.SC, self.mbs, self.tip, self.kind, self.n, self.EA, self.GA = SC, mbs, tip, kind, n, EA, GA

    def coordinates(self):
        return len(self.mbs.systemData.GetODE2Coordinates())


def _ground_coordinate(mbs):
    return mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))


def _fix(mbs, ground, node, coordinates):
    for i in coordinates:
        mbs.AddObject(CoordinateConstraint(markerNumbers=[ground, mbs.AddMarker(
            MarkerNodeCoordinate(nodeNumber=node, coordinate=i))]))


def build_ancf(n, L=1.0, EI=1.0, P=3.0, ea_factor=EA_FACTOR, reduced=1, clamp=(0, 1, 3)) -> Case:
    """n ANCF cable elements along x, clamped at x = 0 (coordinates ``clamp`` of the first node
    fixed: x, y, slope y), a dead load P along y on the tip; assembled."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    l = L / n
    EA = ea_factor * EI / l**2
    nodes = [mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[k * l, 0.0, 1.0, 0.0],
                                           initialCoordinates=[0.0, 0.0, 0.0, 0.0])) for k in range(n + 1)]
    for a, b in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectANCFCable2D(nodeNumbers=[a, b], length=l, massPerLength=0.0, bendingStiffness=EI,
                                        axialStiffness=EA, useReducedOrderIntegration=reduced))
    _fix(mbs, _ground_coordinate(mbs), nodes[0], clamp)
    mbs.AddLoad(LoadForceVector(markerNumber=mbs.AddMarker(MarkerNodePosition(nodeNumber=nodes[-1])),
                                loadVector=[0.0, P, 0.0]))
    mbs.Assemble()
    return Case(SC, mbs, nodes[-1], "ancf", n, EA)


def build_ge(n, L=1.0, EI=1.0, P=3.0, ea_factor=EA_FACTOR, shear=1.0) -> Case:
    """n geometrically exact 2D beams along x (GA = ``shear`` · EA), clamped at x = 0, a dead
    load P along y on the tip; assembled. ``shear=100`` is spacar.compare.exudyn_static's model."""
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    l = L / n
    EA = ea_factor * EI / l**2
    nodes = [mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[k * l, 0.0, 0.0], initialCoordinates=[0.0, 0.0, 0.0]))
             for k in range(n + 1)]
    for a, b in zip(nodes[:-1], nodes[1:]):
        mbs.AddObject(ObjectBeamGeometricallyExact2D(nodeNumbers=[a, b], length=l, massPerLength=0.0,
                                                     bendingStiffness=EI, axialStiffness=EA,
                                                     shearStiffness=shear * EA, includeReferenceRotations=False))
    _fix(mbs, _ground_coordinate(mbs), nodes[0], (0, 1, 2))
    mbs.AddLoad(Force(markerNumber=mbs.AddMarker(MarkerNodeRigid(nodeNumber=nodes[-1])), loadVector=[0.0, P, 0.0]))
    mbs.Assemble()
    return Case(SC, mbs, nodes[-1], "ge", n, EA, shear * EA)


def settings(steps=1, tolerance=1e-8, residual_mode=1, adaptive=True, max_iterations=50, linear_solver="EigenSparse"):
    """SolveStatic's settings: ``steps`` load steps (adaptive: exudyn cuts a failing step and
    grows it again), full Newton, convergence on the increment (``residual_mode=1``) or exudyn's
    default residual criterion (0; relative tolerance ``tolerance``, absolute 1e-2 of it);
    ``linear_solver`` a name of exu.LinearSolverType (EigenSparse, EigenDense, EXUdense)."""
    s = exu.SimulationSettings()
    s.solution.file.write = False
    s.solution.sensors.active = False
    st = s.staticSolver
    st.numberOfLoadSteps = int(steps)
    st.adaptiveStep = bool(adaptive)
    st.computeLoadsJacobian = 0
    st.verboseMode = 0
    nw = st.newton
    nw.useModifiedNewton = False
    nw.maxIterations = int(max_iterations)
    nw.residualMode = int(residual_mode)
    nw.relativeTolerance = tolerance
    nw.absoluteTolerance = tolerance if residual_mode == 1 else tolerance * 1e-2
    s.linearSolver.solverType = getattr(exu.LinearSolverType, linear_solver)
    s.show.statistics = False
    s.show.computationTime = False
    s.show.globalTimers = False
    return s


def tip(case):
    """The tip's current position (x, y)."""
    return np.asarray(case.mbs.GetNodeOutput(case.tip, exu.OutputVariableType.Position)[:2], dtype=float)


def solve(case, simulation_settings) -> dict:
    """One SolveStatic from the straight beam (the model's initial state; the model can be solved
    again): converged?, the tip, Newton iterations and load steps in all, wall time of
    SolveStatic alone."""
    t0 = time.perf_counter()
    try:
        ok = bool(case.mbs.SolveStatic(simulation_settings))
    except Exception:  # exudyn raises on a failed solve (no Newton convergence, step below minimum)
        ok = False
    wall = time.perf_counter() - t0
    it = case.mbs.sys["staticSolver"].it
    return {"ok": ok, "tip": tip(case) if ok else None, "iterations": int(it.newtonStepsCount),
            "steps": max(int(it.currentStepIndex) - 1, 0), "wall": wall}
