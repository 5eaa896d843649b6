"""exudyn's side of the spatial cantilever of benchmarks/stiff_scaling.py (the model of
benchmarks/error_control.py's ``spatial``): n BEAMs of a 1 m steel cantilever along x, clamped at
x = 0, bending about y and z (EIz = 4 EIy), gravity off both axes, as n
``ObjectBeamGeometricallyExact`` elements (Simo–Reissner, interpolated on SE(3))::

    import _exudyn_beam3d as B
    em = B.build(16, rotary=6.5e-6)                    # built and assembled
    r = em.solve(t_end=0.2, n_out=1, solver="generalized_alpha", step=1e-4)
    r.x[-1]                                            # the tip's y and z (em.labels)

* Nodes: ``NodeRigidBodyRxyz`` (position and Tait–Bryan angles). exudyn's Lie-group node
  ``NodeRigidBodyRotVecLG`` is meant for its explicit Lie-group integrators: under
  generalized-α its Newton iteration fails at every step above 1e-5 s here (16 elements: 888
  steps and 5.6 s for the first 0.01 s), while with Tait–Bryan angles (or Euler parameters, the
  same tip) it converges at 5e-4 s in 12 ms. The rotations stay far from the angles' singularity
  (the tip turns by a few hundredths of a radian).
* Rotary inertia: without any about y and z the section rotations carry no mass and exudyn's
  error falls only as the first power of the step (4 elements, 0.05 s: 2.7e-5, 1.2e-5, 6.9e-6 m
  at 4e-4, 2e-4, 1e-4 s); with a steel section's ρI = 6.5e-6 kg m it is 2.2e-6 m at 4e-4 s. The
  benchmark gives both programs that inertia (``rotary``; spacar's EMASS ρA ρIp ρIy ρIz).
* Section: spacar's axially rigid, shear-rigid beam becomes the penalty stiffnesses EA = GA =
  ``penalty`` · EI (default 1e4, as the planar comparison's ANCF cables), torsion GJ = EI, bending
  EIy = EI, EIz = 4 EI; mass ρA per length, rotary inertia ρIp = 1e-4 about the axis and
  ``rotary`` about y and z, as spacar's model.
* The root node's six coordinates are held by ``CoordinateConstraint``; gravity is a
  ``LoadMassProportional`` on every element.

The discretizations differ (linear interpolation with shear against spacar's exact beam
deformations), so the benchmark measures exudyn's error against its own tight solution.
"""
from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np

EI, RHO_A, RHO_IP, G = 175.0, 0.785, 1e-4, 9.81


class SpatialCantilever:
    """The assembled exudyn model; ``labels``: (node, coordinate) of spacar's numbering for the
    two quantities ``solve`` returns (the tip node's y and z)."""

    def __init__(self, n: int, penalty: float = 1e4, rotary: float = 0.0):
        import exudyn as exu
        from exudyn.itemInterface import (CoordinateConstraint, LoadMassProportional, MarkerBodyMass,
                                          MarkerNodeCoordinate, NodePointGround, NodeRigidBodyRxyz,
                                          ObjectBeamGeometricallyExact)

        self.SC = exu.SystemContainer()
        mbs = self.mbs = self.SC.AddSystem()
        length = 1.0 / n
        section = exu.BeamSection()
        section.stiffnessMatrix = np.diag([penalty * EI, penalty * EI, penalty * EI, EI, EI, 4.0 * EI])
        section.inertia = np.diag([RHO_IP, rotary, rotary])
        section.massPerLength = RHO_A
        nodes = [mbs.AddNode(NodeRigidBodyRxyz(referenceCoordinates=[i * length, 0, 0, 0, 0, 0])) for i in range(n + 1)]
        beams = [mbs.AddObject(ObjectBeamGeometricallyExact(nodeNumbers=[nodes[i], nodes[i + 1]], length=length,
                                                            sectionData=section)) for i in range(n)]
        ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
        for c in range(6):
            root = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=c))
            mbs.AddObject(CoordinateConstraint(markerNumbers=[ground, root]))
        for b in beams:
            mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=b)),
                                             loadVector=[0.0, -G, -0.5 * G]))
        mbs.Assemble()
        self.tip = nodes[-1]
        self.labels = [(n + 1, 2), (n + 1, 3)]

    def solve(self, t_end, n_out=1, solver="generalized_alpha", step=1e-4, configure=None):
        """One run from the straight beam at rest to t_end at fixed steps; returns x (the tip's y
        and z at the end, one row) and stats (wall time, steps)."""
        import exudyn as exu
        from spacar.compare.exudyn import SOLVERS, simulation_settings

        s = simulation_settings(self.mbs, 0.0, t_end, solver, None, None, step)
        if configure is not None:
            configure(s)
        start = time.perf_counter()
        ok = self.mbs.SolveDynamic(s, solverType=getattr(exu.DynamicSolverType, SOLVERS[solver]))
        wall = time.perf_counter() - start
        if ok is False:
            raise RuntimeError(f"exudyn's {solver} failed at step {step}")
        p = np.asarray(self.mbs.GetNodeOutput(self.tip, exu.OutputVariableType.Position))
        if not np.all(np.isfinite(p)) or np.abs(p).max() > 10.0:
            raise RuntimeError(f"exudyn's {solver} diverged at step {step}")
        return SimpleNamespace(x=np.array([[p[1], p[2]]]), stats={"wall_time": wall, "steps": s.timeIntegration.numberOfSteps})


def build(n: int, penalty: float = 1e4, rotary: float = 0.0) -> SpatialCantilever:
    return SpatialCantilever(n, penalty, rotary)
