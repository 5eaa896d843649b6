"""The equivalent exudyn model of a spacar model, its simulation, and side-by-side results.

Two formulations:

* ``formulation="redundant"`` (default): every rigid body is an exudyn rigid body (planar:
  ``NodeRigidBody2D``/``ObjectRigidBody2D`` with the node at the centre of mass; spatial:
  ``CreateRigidBody`` with Euler parameters), joints are constraints, and the equations are a
  DAE solved by exudyn's implicit solvers (generalized-α by default, fixed step). Supports closed
  loops (four-bar), sliders and flexible planar beams.
* ``formulation="tree"``: one ``ObjectKinematicTree`` in minimal (relative joint) coordinates —
  an ODE, so exudyn's explicit error-controlled integrators (DOPRI5, RK67, ODE23) apply. Kinematic
  trees of rigid bodies with revolute joints only.

Supported spacar input (anything else raises :class:`spacar.compare.UnsupportedModelError`):

* rigid bodies made of rigid PLBEAM/PLBEAMNL or BEAM/BEAMNL elements (all deformations fixed),
  with MASS on position nodes, on BETA nodes (Izz), on LAMBDA nodes (inertia tensor), EMASS ρA
  and the BEAM rotary-inertia extension;
* joints: position nodes shared by bodies — revolute about z (planar) or about the HINGE axis,
  spherical otherwise (spatial; redundant formulation only); PLHINGE ``ESTIFF``/``EDAMPP`` as a
  coordinate spring-damper on the two rotation coordinates (planar; also in the tree
  formulation as joint P/D gains); HINGE springs are not converted;
* the ground: fully fixed position nodes, fixed BETA/LAMBDA nodes;
* sliders: a partly fixed position node on one rigid body (``ObjectJointPrismatic2D``) or on a
  flexible beam (``CoordinateConstraint``);
* a prescribed BETA rotation (``INPUTX``, e.g. the slider-crank's crank): a velocity-level
  coordinate constraint θ̇ = ω0 when the input acceleration is zero, otherwise a constraint with
  an offset user function β0 + ω0 t + ½α0 t² (redundant formulation);
* flexible planar beams: PLBEAM/PLBEAMNL with released or DYNE bending deformations become
  ``ObjectANCFCable2D`` elements (same cubic Hermite interpolation and consistent mass as
  spacar's PLBEAM, ρA, EI; exact nonlinear curvature instead of spacar's co-rotational bending
  deformations); BETA nodes shared by beams become shared ANCF nodes (straight beams only);
  the axial stiffness is EA when e1 is released, otherwise a penalty ``axial_stiffness``
  (default ``DEFAULT_AXIAL_RATIO``·EI/l0² = 1e4·EI/l0²) because ANCF elements have no
  inextensible variant and lock in bending when EA is much larger; clamped ends (fixed
  BETA node), pins to rigid bodies and to the ground, sliders and point masses on beam nodes.
  Beams clamped to moving rigid bodies and EDAMPP are not converted.
* ``GRAVITY``.

Results are mapped back onto spacar's nodal coordinates x (same column order; for ANCF nodes the
BETA value is the slope angle minus the reference angle) and spacar's deformations e are
evaluated from them with spacar's own element kernels, so both programs are compared in the
same numbers (``ExudynResults.x``, ``.e`` against ``spacar.Results.x``, ``.e``).
"""
from __future__ import annotations

import functools
import math
import time as _time

import numpy as np

try:
    import exudyn as exu
    from exudyn.itemInterface import (
        LoadMassProportional,
        MarkerBodyMass,
        MarkerBodyPosition,
        MarkerNodeCoordinate,
        MarkerNodePosition,
        NodeGenericODE2,
        NodePoint2DSlope1,
        NodePointGround,
        NodeRigidBody2D,
        ObjectANCFCable2D,
        ObjectConnectorCoordinate,
        ObjectConnectorCoordinateSpringDamper,
        ObjectGround,
        ObjectJointPrismatic2D,
        ObjectJointRevolute2D,
        ObjectKinematicTree,
        ObjectMassPoint2D,
        ObjectRigidBody2D,
    )
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("spacar.compare.exudyn needs exudyn: pip install 'spacar[compare]' (from a clone of spacar: pip install '.[compare]')") from exc

from .. import _core
from ._topology import (
    PeerResultError,
    UnsupportedModelError,
    analyse,
    lambda_of_rotation,
    rot_z,
)

SOLVERS = {
    "generalized_alpha": "GeneralizedAlpha",
    "trapezoidal": "TrapezoidalIndex2",
    "dopri5": "DOPRI5",
    "rk67": "RK67",
    "dverk6": "DVERK6",
    "ode23": "ODE23",
    "rk44": "RK44",
}
EXPLICIT = ("dopri5", "rk67", "dverk6", "ode23", "rk44")
ADAPTIVE = ("dopri5", "ode23")  # exudyn's error-controlled explicit methods

# Penalty axial stiffness of ANCF cables for spacar beams with a rigid elongation, as EA l0²/EI.
# ANCF cable elements lock in bending when EA l0²/EI is large (their axial strain cannot vanish
# along a bent cubic element): on the manual's slider-crank the bending deformations come out
# 20 % too small at 1e5 and 40 % at 3e5, while below ~1e3 the axial compliance shows. 1e4 keeps
# both effects at a few per cent (docs/comparison.md).
DEFAULT_AXIAL_RATIO = 1e4


def _axis_frame(a) -> np.ndarray:
    """A rotation matrix A with A e_z = a (a unit vector)."""
    a = np.asarray(a, dtype=float)
    a = a / np.linalg.norm(a)
    t = np.eye(3)[int(np.argmin(np.abs(a)))]
    x = np.cross(t, a)
    x /= np.linalg.norm(x)
    y = np.cross(a, x)
    return np.column_stack([x, y, a])


def _rot_axis(a, th) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(th) * K + (1 - math.cos(th)) * K @ K


class ExudynResults:
    """exudyn results on spacar's coordinates: ``t`` (nt,), ``x`` (nt, nx) in spacar's column
    order, ``e`` (nt, ne) evaluated with spacar's element kernels from ``x`` (NaN for elements
    whose nodes are not all mapped), ``q`` (tree formulation: joint coordinates), ``stats``
    (wall time, steps, …)."""

    def __init__(self, t, x, e, q, stats, coordinate_labels, deformation_labels):
        self.t, self.x, self.e, self.q, self.stats = t, x, e, q, stats
        self.coordinate_labels = coordinate_labels
        self.deformation_labels = deformation_labels
        self._coord = {lbl: i for i, lbl in enumerate(coordinate_labels)}
        self._def = {lbl: i for i, lbl in enumerate(deformation_labels)}

    def coordinate(self, n, i):
        return self.x[:, self._coord[(n, i)]]

    def deformation(self, e, i):
        return self.e[:, self._def[(e, i)]]

    def __repr__(self):
        return f"<spacar.compare.exudyn.ExudynResults: {len(self.t)} times, {self.x.shape[1]} coordinates>"


def simulation_settings(mbs, t_start, t_end, solver, rtol, atol, step):
    """exudyn's SimulationSettings for one quiet run of ``mbs`` from t_start to t_end: no files,
    sensors or printing; the error-controlled ``solver`` (ADAPTIVE) with rtol and atol when step
    is None, else fixed steps of about ``step``; the sparse solver beyond 200 coordinates."""
    s = exu.SimulationSettings()
    s.solution.file.write = False
    s.solution.sensors.active = False
    s.show.computationTime = False
    s.show.statistics = False
    s.show.globalTimers = False
    ti = s.timeIntegration
    ti.verboseMode = 0
    ti.startTime = t_start
    ti.endTime = t_end
    if solver in ADAPTIVE and step is None:
        ti.automaticStepSize = True
        ti.relativeTolerance = rtol
        ti.absoluteTolerance = atol
        ti.numberOfSteps = 1
        ti.minimumStepSize = 1e-14
    else:
        if step is None:
            raise ValueError(f"solver {solver!r} needs a fixed step")
        ti.automaticStepSize = False
        ti.numberOfSteps = max(1, int(round((t_end - t_start) / step)))
    if len(mbs.systemData.GetODE2Coordinates()) > 200:
        s.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    return s


class ExudynModel:
    """An exudyn model equivalent to a spacar model. ``SC``, ``mbs``: exudyn's system container
    and main system (assembled); ``topology``: the analysis of the spacar model."""

    def __init__(self, spacar_model, formulation: str = "redundant", axial_stiffness=None):
        if formulation not in ("redundant", "tree"):
            raise ValueError("formulation must be 'redundant' or 'tree'")
        self.spacar_model = spacar_model
        self.formulation = formulation
        self.sim = _core.Simulation(spacar_model.core)
        self.sim.assemble()
        self.topology = topo = analyse(spacar_model, self.sim)
        self.t0 = spacar_model.current_time
        self.labels = [tuple(lbl) for lbl in self.sim.system.coord_label]
        self.def_labels = [tuple(lbl) for lbl in self.sim.system.def_label]
        self.SC = exu.SystemContainer()
        self.mbs = self.SC.AddSystem()
        self._axial_stiffness = axial_stiffness
        if formulation == "tree":
            self._build_tree()
        elif topo.planar:
            self._build_planar()
        else:
            self._build_spatial()
        self.mbs.Assemble()
        self._kernels = self._element_kernels()

    # --- planar, redundant coordinates ---------------------------------------------------

    def _build_planar(self):
        topo, mbs = self.topology, self.mbs
        x0, xd0 = topo.x0, topo.xd0
        ci = topo.coord_index
        ground = mbs.AddObject(ObjectGround(referencePosition=[0.0, 0.0, 0.0]))
        self._ground = ground
        ground_coord = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=mbs.AddNode(NodePointGround()), coordinate=0))
        g = np.array(topo.gravity, dtype=float)
        self._bodies = {}   # body index -> (node, object, anchor, com - anchor local)
        body_marker = {}

        def marker_at(b, n):
            key = (b, n)
            if key not in body_marker:
                if b == 0:
                    p = topo.bodies[0].points[n]
                    body_marker[key] = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=list(p)))
                else:
                    bd = topo.bodies[b]
                    local = bd.points[n] - bd.com
                    body_marker[key] = mbs.AddMarker(MarkerBodyPosition(bodyNumber=self._bodies[b][1], localPosition=list(local)))
            return body_marker[key]

        for bd in topo.bodies[1:]:
            if bd.mass <= 0:
                raise UnsupportedModelError(f"the body of BETA nodes {bd.orientation_nodes} has no mass (exudyn's rigid bodies need one)")
            anchor = topo.body_anchor(bd.index)
            beta = topo.body_angle(bd.index, x0)
            R = rot_z(beta)
            pa = topo.point_position(anchor, x0)
            va = topo.point_position(anchor, xd0)
            w = topo.body_omega(bd.index, x0, xd0)
            c = pa + R @ (bd.com - bd.points[anchor])
            vc = va + np.cross(w, R @ (bd.com - bd.points[anchor]))
            node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[0.0, 0.0, 0.0],
                                               initialCoordinates=[c[0], c[1], beta],
                                               initialVelocities=[vc[0], vc[1], w[2]]))
            obj = mbs.AddObject(ObjectRigidBody2D(mass=bd.mass, inertia=bd.inertia_com[2, 2], nodeNumber=node))
            self._bodies[bd.index] = (node, obj)
            if np.any(g):
                mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=obj)),
                                                 loadVector=[g[0], g[1], 0.0]))
            if bd.driven is not None:
                dr = bd.driven
                rot = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=node, coordinate=2))
                if dr.alpha0 == 0.0:
                    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground_coord, rot], offset=dr.omega0, velocityLevel=True))
                else:
                    def offset(mbs_, t, item, lOffset, dr=dr):
                        s = t - dr.t0
                        return dr.beta0 + dr.omega0 * s + 0.5 * dr.alpha0 * s * s
                    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground_coord, rot], offsetUserFunction=offset))

        # flexible beams: ANCF cable elements on shared nodes
        self._ancf = {}  # position node -> (ancf node, slope angle reference α0, BETA node)
        self._ancf_beta = {}  # BETA node -> position node carrying its slope
        for fb in topo.flexible:
            p, rp, q, rq = fb.nodes
            for pos, beta_node in ((p, rp), (q, rq)):
                if beta_node in self._ancf_beta and self._ancf_beta[beta_node] != pos:
                    raise UnsupportedModelError(f"BETA node {beta_node} is used at two positions of flexible beams")
                if pos in self._ancf:
                    if self._ancf[pos][2] != beta_node:
                        raise UnsupportedModelError(
                            f"position node {pos} joins flexible beams with different BETA nodes (a pin between beams); not converted")
                    continue
                xy = topo.point_position(pos, x0)
                vxy = topo.point_position(pos, xd0)
                b0 = x0[ci[(beta_node, 1)]]
                bd0 = xd0[ci[(beta_node, 1)]]
                phi = fb.alpha0 + b0
                slope = [math.cos(phi), math.sin(phi)]
                dslope = [-math.sin(phi) * bd0, math.cos(phi) * bd0]
                node = mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[xy[0], xy[1], slope[0], slope[1]],
                                                     initialCoordinates=[0.0, 0.0, 0.0, 0.0],
                                                     initialVelocities=[vxy[0], vxy[1], dslope[0], dslope[1]]))
                self._ancf[pos] = (node, fb.alpha0, beta_node)
                self._ancf_beta[beta_node] = pos
            ea = fb.ea if fb.ea is not None else (self._axial_stiffness if self._axial_stiffness is not None
                                                   else DEFAULT_AXIAL_RATIO * fb.ei / fb.l0**2)
            cable = mbs.AddObject(ObjectANCFCable2D(nodeNumbers=[self._ancf[p][0], self._ancf[q][0]], length=fb.l0,
                                                    massPerLength=fb.rho_a, bendingStiffness=fb.ei, axialStiffness=ea))
            if np.any(g) and fb.rho_a > 0:
                mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=cable)),
                                                 loadVector=[g[0], g[1], 0.0]))
        for n, m in topo.point_masses.items():
            mbs.AddObject(ObjectMassPoint2D(mass=m, nodeNumber=self._ancf[n][0]))
        for pos, (node, alpha0, beta_node) in self._ancf.items():
            owners = topo.bodies_of_point.get(pos, [])
            for b in owners:
                if b == 0:  # pinned to the ground
                    for k in range(2):
                        mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground_coord, mbs.AddMarker(
                            MarkerNodeCoordinate(nodeNumber=node, coordinate=k))], offset=float(topo.bodies[0].points[pos][k])))
                else:
                    mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[marker_at(b, pos), mbs.AddMarker(MarkerNodePosition(nodeNumber=node))]))
            for k in topo.partial_fix.get(pos, []):
                mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground_coord, mbs.AddMarker(
                    MarkerNodeCoordinate(nodeNumber=node, coordinate=k))], offset=float(x0[ci[(pos, k + 1)]])))
            if topo.body_of_orientation.get(beta_node) == 0:  # clamped
                phi = alpha0 + x0[ci[(beta_node, 1)]]
                c, s = math.cos(phi), math.sin(phi)
                comps = [1] if abs(s) < 1e-14 else [0] if abs(c) < 1e-14 else [0, 1]
                for k in comps:
                    mbs.AddObject(ObjectConnectorCoordinate(markerNumbers=[ground_coord, mbs.AddMarker(
                        MarkerNodeCoordinate(nodeNumber=node, coordinate=2 + k))], offset=(c, s)[k]))

        # joints between rigid bodies
        for j in topo.joints:
            a, b = j.bodies
            mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[marker_at(a, j.node), marker_at(b, j.node)]))
            if j.stiffness or j.damping:
                # spacar: σ1 = St e1 + d ė1 with e1 = ±(β_b − β_a); exudyn: k (q_m1 − q_m0 − offset) + d (q̇_m1 − q̇_m0),
                # the ground's coordinate marker reads 0
                off = 0.0
                if a == 0:
                    off = topo.body_angle(0, x0)
                elif b == 0:
                    off = -topo.body_angle(0, x0)
                mbs.AddObject(ObjectConnectorCoordinateSpringDamper(
                    markerNumbers=[self._rotation_marker(a, ground_coord), self._rotation_marker(b, ground_coord)],
                    stiffness=j.stiffness, damping=j.damping, offset=off))
        # sliders on rigid bodies
        for n, comps in topo.partial_fix.items():
            if n in self._ancf:
                continue
            (b,) = topo.bodies_of_point[n]
            if len(comps) != 1:
                raise UnsupportedModelError(f"node {n}: a planar node with both components fixed belongs to the ground")
            k = comps[0]
            normal = [0.0, 0.0, 0.0]
            normal[k] = 1.0
            axis = [0.0, 0.0, 0.0]
            axis[1 - k] = 1.0
            p = topo.point_position(n, x0)
            gm = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[p[0], p[1], 0.0]))
            mbs.AddObject(ObjectJointPrismatic2D(markerNumbers=[marker_at(b, n), gm], axisMarker0=axis,
                                                 normalMarker1=normal, constrainRotation=False))

    def _rotation_marker(self, b, ground_coord):
        if b == 0:
            return ground_coord
        return self.mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=self._bodies[b][0], coordinate=2))

    # --- spatial, redundant coordinates --------------------------------------------------

    def _build_spatial(self):
        from exudyn.utilities import RigidBodyInertia

        topo, mbs = self.topology, self.mbs
        if topo.flexible:
            raise UnsupportedModelError("flexible spatial beams are not converted to exudyn")
        if topo.partial_fix:
            raise UnsupportedModelError(f"partly fixed nodes {sorted(topo.partial_fix)} of a spatial model are not converted")
        x0, xd0 = topo.x0, topo.xd0
        ground = mbs.CreateGround(referencePosition=[0.0, 0.0, 0.0])
        self._ground = ground
        self._bodies = {}
        for bd in topo.bodies[1:]:
            if bd.mass <= 0:
                raise UnsupportedModelError(f"the body of LAMBDA nodes {bd.orientation_nodes} has no mass")
            if bd.driven is not None:
                raise UnsupportedModelError("prescribed rotations of spatial bodies are not converted")
            anchor = topo.body_anchor(bd.index)
            R = topo.body_rotation(bd.index, x0)
            pa, va = topo.point_position(anchor, x0), topo.point_position(anchor, xd0)
            w = topo.body_omega(bd.index, x0, xd0)
            r = R @ (bd.com - bd.points[anchor])
            obj = mbs.CreateRigidBody(referencePosition=list(pa + r), referenceRotationMatrix=R,
                                      initialVelocity=list(va + np.cross(w, r)), initialAngularVelocity=list(w),
                                      inertia=RigidBodyInertia(mass=bd.mass, inertiaTensor=bd.inertia_com,
                                                               com=[0.0, 0.0, 0.0], inertiaTensorAtCOM=True),
                                      gravity=list(topo.gravity))
            self._bodies[bd.index] = (mbs.GetObject(obj)["nodeNumber"], obj)

        def item(b):
            return ground if b == 0 else self._bodies[b][1]

        for j in topo.joints:
            a, b = j.bodies
            p = topo.point_position(j.node, x0)
            if j.kind == "revolute":
                if j.stiffness or j.damping:
                    raise UnsupportedModelError("HINGE springs/dampers are not converted to exudyn")
                axis = topo.body_rotation(a, x0) @ j.axis
                mbs.CreateRevoluteJoint(itemNumbers=[item(a), item(b)], position=list(p), axis=list(axis), useGlobalFrame=True)
            else:
                mbs.CreateSphericalJoint(itemNumbers=[item(a), item(b)], position=list(p), useGlobalFrame=True)

    # --- kinematic tree --------------------------------------------------------------------

    def _build_tree(self):
        topo, mbs = self.topology, self.mbs
        if topo.flexible or topo.partial_fix or any(b.driven for b in topo.bodies):
            raise UnsupportedModelError("the tree formulation takes rigid bodies with revolute joints only "
                                        "(no flexible beams, sliders or prescribed motions)")
        tree = topo.tree()
        if any(j.kind != "revolute" for j, _, _ in tree):
            raise UnsupportedModelError("the tree formulation takes revolute joints only (spherical joints: formulation='redundant')")
        self._tree = tree
        frame = {0: np.eye(3)}       # A_b: rotation from the body frame to the link frame
        origin = {0: np.zeros(3)}
        link = {0: -1}
        offsets, transforms, coms, inertias, masses, parents = [], [], [], [], [], []
        P, D = [], []
        for k, (j, p, c) in enumerate(tree):
            bc = topo.bodies[c]
            A_c = np.eye(3) if topo.planar else _axis_frame(j.axis)
            A_p = frame[p]
            pivot = topo.bodies[p].points[j.node]
            if p == 0:
                offsets.append(list(pivot))
                transforms.append(topo.ground_rotation @ A_c)
            else:
                offsets.append(list(A_p.T @ (pivot - origin[p])))
                transforms.append(A_p.T @ A_c)
            frame[c] = A_c
            origin[c] = bc.points[j.node]
            link[c] = k
            parents.append(link[p])
            coms.append(list(A_c.T @ (bc.com - origin[c])))
            inertias.append(A_c.T @ bc.inertia_com @ A_c)
            masses.append(bc.mass)
            P.append(j.stiffness)
            D.append(j.damping)
        self._frame, self._origin = frame, origin
        q0, v0 = self._tree_state_from_spacar(topo.x0, topo.xd0, np.array(self.sim.data.e), np.array(self.sim.data.ed))
        n = len(tree)
        node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n, initialCoordinates=list(q0),
                                           initialCoordinates_t=list(v0), numberOfODE2Coordinates=n))
        kw = {}
        if any(P) or any(D):
            kw = dict(jointPControlVector=P, jointDControlVector=D,
                      jointPositionOffsetVector=[0.0] * n, jointVelocityOffsetVector=[0.0] * n)
        self._tree_object = mbs.AddObject(ObjectKinematicTree(
            nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * n, linkParents=parents,
            jointTransformations=exu.Matrix3DList(transforms), jointOffsets=exu.Vector3DList(offsets),
            linkInertiasCOM=exu.Matrix3DList(inertias), linkCOMs=exu.Vector3DList(coms), linkMasses=masses,
            gravity=list(topo.gravity), **kw))
        self._tree_node = node

    def _tree_state_from_spacar(self, x, xd, e, ed):
        topo = self.topology
        q, v = [], []
        for j, p, c in self._tree:
            if j.hinge is not None:
                col = topo.def_index[(j.hinge[0], 1)]
                q.append(j.hinge[1] * e[col])
                v.append(j.hinge[1] * ed[col])
            else:
                q.append(topo.body_angle(c, x) - topo.body_angle(p, x))
                v.append(topo.body_omega(c, x, xd)[2] - topo.body_omega(p, x, xd)[2])
        return np.array(q), np.array(v)

    # --- state → spacar coordinates -------------------------------------------------------

    def _element_kernels(self):
        kernels = []
        n_deformations = {t.name: t.n_deformations for t in _core.element_catalogue()}
        ci, di = self.topology.coord_index, self.topology.def_index
        for k, el in sorted(self.spacar_model.elements.items()):
            cols = []
            for n in el.nodes:
                size = _core.node_size(self.spacar_model.nodes[n].kind)
                cols += [ci[(n, i)] for i in range(1, size + 1)]
            properties = {"params": list(el.params), "l0": el.l0 if el.l0 is not None else 1.0,
                          "lgeomy": list(el.lgeomy)}
            kern = functools.partial(_core.element_deformations, el.type_name, **properties)
            dcols = [di[(k, i)] for i in range(1, n_deformations[el.type_name] + 1)]
            kernels.append((kern, cols, dcols, el.type_name))
        return kernels

    def _deformations(self, xs):
        """spacar's deformations of the states xs (one row each); NaN for an element with a
        non-finite coordinate."""
        e = np.full((len(xs), len(self.def_labels)), np.nan)
        for kern, cols, dcols, _ in self._kernels:
            xe = xs[:, cols]
            finite = np.all(np.isfinite(xe), axis=1)
            if finite.any():
                e[np.ix_(finite, dcols)] = kern(xe[finite])
        return e

    def current_x(self, previous=None) -> np.ndarray:
        """spacar's nodal coordinates from exudyn's current state; ``previous`` (x at the last
        output) keeps angles continuous."""
        topo, mbs = self.topology, self.mbs
        ci = topo.coord_index
        x = np.full(len(self.labels), np.nan)
        # ground
        for n, p in topo.bodies[0].points.items():
            k = 2 if topo.planar else 3
            for i in range(k):
                x[ci[(n, i + 1)]] = p[i]
        for n in topo.bodies[0].orientation_nodes:
            for i in range(1 if topo.planar else 4):
                x[ci[(n, i + 1)]] = topo.x0[ci[(n, i + 1)]]
        if self.formulation == "tree":
            q = np.asarray(mbs.GetNodeOutput(self._tree_node, exu.OutputVariableType.Coordinates))
            rot = {0: topo.ground_rotation}
            ang = {0: topo.body_angle(0, topo.x0)} if topo.planar else {}
            pos = {0: np.zeros(3)}  # position of the link origin; ground: global frame
            for k, (j, p, c) in enumerate(self._tree):
                piv = topo.bodies[p].points[j.node]
                pos[c] = piv if p == 0 else pos[p] + rot[p] @ (piv - self._origin[p])
                if topo.planar:
                    ang[c] = ang[p] + q[k]
                    rot[c] = rot_z(ang[c])
                else:
                    rot[c] = rot[p] @ _rot_axis(j.axis, q[k])
            for b in topo.bodies[1:]:
                self._write_body(x, b, rot[b.index], ang.get(b.index), lambda r, b=b: pos[b.index] + rot[b.index] @ (r - self._origin[b.index]), previous)
            return x, q
        if topo.planar:
            for b in topo.bodies[1:]:
                node = self._bodies[b.index][0]
                c = mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates)
                R = rot_z(c[2])
                self._write_body(x, b, R, c[2], lambda r, b=b, c=c, R=R: np.array([c[0], c[1], 0.0]) + R @ (r - b.com), previous)
            for pos, (node, alpha0, beta_node) in self._ancf.items():
                c = mbs.GetNodeOutput(node, exu.OutputVariableType.Coordinates)
                ref = mbs.GetNode(node)["referenceCoordinates"]
                tot = np.asarray(c) + np.asarray(ref)
                x[ci[(pos, 1)]], x[ci[(pos, 2)]] = tot[0], tot[1]
                beta = math.atan2(tot[3], tot[2]) - alpha0
                near = previous[ci[(beta_node, 1)]] if previous is not None else topo.x0[ci[(beta_node, 1)]]
                x[ci[(beta_node, 1)]] = beta + 2 * math.pi * round((near - beta) / (2 * math.pi))
        else:
            for b in topo.bodies[1:]:
                node = self._bodies[b.index][0]
                p = np.asarray(mbs.GetNodeOutput(node, exu.OutputVariableType.Position))
                R = np.asarray(mbs.GetNodeOutput(node, exu.OutputVariableType.RotationMatrix)).reshape(3, 3)
                self._write_body(x, b, R, None, lambda r, b=b, p=p, R=R: p + R @ (r - b.com), previous)
        return x, None

    def _write_body(self, x, b, R, angle, place, previous):
        topo = self.topology
        ci = topo.coord_index
        for n, r in b.points.items():
            if 0 in topo.bodies_of_point.get(n, []) and b.index != 0:
                continue
            p = place(r)
            for i in range(2 if topo.planar else 3):
                x[ci[(n, i + 1)]] = p[i]
        for n in b.orientation_nodes:
            if topo.planar:
                x[ci[(n, 1)]] = angle
            else:
                near = previous[[ci[(n, i)] for i in range(1, 5)]] if previous is not None else \
                    topo.x0[[ci[(n, i)] for i in range(1, 5)]]
                lam = lambda_of_rotation(R, near=near)
                for i in range(4):
                    x[ci[(n, i + 1)]] = lam[i]

    # --- simulation -----------------------------------------------------------------------

    def settings(self, t_start, t_end, solver, rtol, atol, step):
        return simulation_settings(self.mbs, t_start, t_end, solver, rtol, atol, step)

    def solve(self, t_end=None, n_out=None, solver=None, rtol=None, atol=None, step=None, times=None,
              configure=None) -> ExudynResults:
        """Simulate from spacar's initial state (time of the model) to t_end, with output at
        ``n_out`` + 1 equally spaced times (or ``times``); defaults from the model's TIMESTEP.

        ``solver``: ``"dopri5"``/``"ode23"`` (error-controlled; ``rtol``, ``atol``, default
        spacar's EPSINT and 1e-3·EPSINT), ``"rk67"``, ``"dverk6"``, ``"rk44"`` (fixed ``step``),
        ``"generalized_alpha"`` (default for the redundant formulation), ``"trapezoidal"``
        (implicit, fixed ``step``, default 1e-4). Explicit methods need the tree formulation (or a
        model without joints). ``configure(settings)`` may adjust exudyn's SimulationSettings.
        The integration restarts at every output time (exudyn's adaptive methods do not stop
        exactly on output times); ask for one output interval to time a single run."""
        s = self.spacar_model.settings
        if times is None:
            t_end = self.t0 + s.timestep_tp if t_end is None else t_end
            n_out = (s.timestep_n if n_out is None else n_out) or 1
            times = np.linspace(self.t0, t_end, n_out + 1)
        times = np.asarray(times, dtype=float)
        if solver is None:
            solver = "dopri5" if self.formulation == "tree" else "generalized_alpha"
        if solver not in SOLVERS:
            raise ValueError(f"solver must be one of {sorted(SOLVERS)}")
        if solver in EXPLICIT and self.formulation != "tree":
            raise UnsupportedModelError("exudyn's explicit solvers do not handle joint constraints; use formulation='tree' "
                                        "or an implicit solver")
        rtol = self.topology.epsint if rtol is None else rtol
        atol = 1e-3 * rtol if atol is None else atol
        if step is None and solver not in ADAPTIVE:
            step = 1e-4
        mbs = self.mbs
        sd = mbs.systemData
        initial = sd.GetSystemState(exu.ConfigurationType.Initial)
        xs = np.empty((len(times), len(self.labels)))
        qs = [] if self.formulation == "tree" else None
        prev, q = self.current_x_initial()
        xs[0] = prev
        if qs is not None:
            qs.append(q)
        stats = {"wall_time": 0.0, "steps": 0, "rejected": 0}
        solver_type = getattr(exu.DynamicSolverType, SOLVERS[solver])
        try:
            for k in range(1, len(times)):
                st = self.settings(times[k - 1], times[k], solver, rtol, atol, step)
                if configure is not None:
                    configure(st)
                start = _time.perf_counter()
                ok = mbs.SolveDynamic(st, solverType=solver_type, storeSolver=True)
                stats["wall_time"] += _time.perf_counter() - start
                if ok is False:
                    raise RuntimeError(f"exudyn's {solver} failed between t = {times[k - 1]} and {times[k]}")
                it = mbs.sys["dynamicSolver"].it
                stats["steps"] += it.currentStepIndex
                stats["rejected"] += getattr(it, "rejectedAutomaticStepSizeSteps", 0)
                x, q = self.current_x(prev)
                _check_peer_state(x, xs[0], solver, times[k])
                if qs is not None:  # the tree's joint coordinates: positions stay bounded when these run away
                    _check_peer_state(np.asarray(q, dtype=float), np.asarray(qs[0], dtype=float), solver, times[k])
                xs[k] = x
                if qs is not None:
                    qs.append(q)
                prev = x
                sd.SetSystemState(sd.GetSystemState(exu.ConfigurationType.Current), exu.ConfigurationType.Initial)
        finally:
            sd.SetSystemState(initial, exu.ConfigurationType.Initial)
        es = self._deformations(xs)  # each element's kernel made once for all output times
        stats["solver"] = solver
        stats["stages"] = mbs.sys["dynamicSolver"].GetNumberOfStages() if solver in EXPLICIT else None
        return ExudynResults(times, xs, es, None if qs is None else np.array(qs), stats, self.labels, self.def_labels)

    def current_x_initial(self):
        """spacar coordinates of exudyn's initial state (as built)."""
        sd = self.mbs.systemData
        cur = sd.GetSystemState(exu.ConfigurationType.Current)
        sd.SetSystemState(sd.GetSystemState(exu.ConfigurationType.Initial), exu.ConfigurationType.Current)
        try:
            return self.current_x()
        finally:
            sd.SetSystemState(cur, exu.ConfigurationType.Current)


# A state whose coordinates grew beyond this many times the initial state's size (plus one
# model length) has diverged: no mechanism of the comparisons moves that far.
_DIVERGED = 1e6


def _check_peer_state(x, x0, solver, t):
    """Raise PeerResultError if exudyn's state at t is not finite or has run away from the start."""
    size = 1.0 + float(np.max(np.abs(x0))) if x0.size else 1.0
    if not np.isfinite(x).all() or (x.size and float(np.max(np.abs(x))) > _DIVERGED * size):
        worst = float(np.max(np.abs(x))) if np.isfinite(x).all() else float("nan")
        raise PeerResultError(f"exudyn's {solver} reported success but returned a diverged state at t = {t:g} "
                              f"(largest coordinate {worst:.3g}, initially {size - 1.0:.3g}): its result is not "
                              "to be trusted; try a smaller step, a tighter tolerance or another solver")


def build(spacar_model, formulation: str = "redundant", axial_stiffness=None) -> ExudynModel:
    """The equivalent :class:`ExudynModel` of a spacar model (see the module docstring)."""
    return ExudynModel(spacar_model, formulation, axial_stiffness)


def side_by_side(spacar_model, formulation="redundant", **solve_options):
    """Run spacar (a copy of the model, its current block) and exudyn over the same output
    times; returns a dict with ``t``, ``x_spacar``, ``x_exudyn``, ``e_spacar``, ``e_exudyn``,
    the labels and both programs' statistics. ``solve_options`` go to :meth:`ExudynModel.solve`."""
    from ..simulate import simulate

    em = build(spacar_model.copy(), formulation, solve_options.pop("axial_stiffness", None))
    res = simulate(spacar_model.copy())
    er = em.solve(times=res.t, **solve_options)
    return {
        "t": res.t, "x_spacar": res.x, "x_exudyn": er.x, "e_spacar": res.e, "e_exudyn": er.e,
        "q_exudyn": er.q, "coordinate_labels": res.coordinate_labels, "deformation_labels": res.deformation_labels,
        "spacar_stats": res.stats, "exudyn_stats": er.stats, "spacar_results": res, "exudyn_results": er,
    }
