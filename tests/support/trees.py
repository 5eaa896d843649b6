"""Trees of rigid bodies for the recursive path's tests (tests/core/test_recursive_trees.py):
planar (PLBEAMs on PLHINGEs or DYNX rotations) and spatial (BEAMs on HINGEs), and models near
them that are not trees."""
from __future__ import annotations

import math

import numpy as np

import spacar
from spacar.compare import models

G = 9.81


def planar_branched_tree(spring=False):
    """A trunk hinged to the ground, two branches hinged at its tip (one hinge points from the
    child to the parent), one branch two beams rigidly joined at a shared BETA node; masses on XY
    and BETA nodes, FORCE on points and a rotation, a hinge spring-damper, gravity with an x
    component; ``spring``: a released hinge with stiffness and damping between the branches."""
    m = spacar.Model()
    for node, xy in {1: (0, 0), 2: (1, 0.2), 3: (1.8, 0.9), 4: (1.6, -0.7), 5: (2.4, -0.5)}.items():
        m.x(node, *xy)
    m.plbeam(1, 1, 11, 2, 12)
    m.plbeam(2, 2, 21, 3, 22)
    m.plbeam(3, 2, 31, 4, 32)
    m.plbeam(4, 4, 32, 5, 42)
    m.plhinge(101, 100, 11)
    m.plhinge(102, 12, 21)
    m.plhinge(103, 31, 12)
    for h in (101, 102, 103):
        m.dyne(h, 1)
    m.fix(1)
    m.fix(100)
    for e, rho in ((1, 1.0), (2, 0.7), (3, 1.3), (4, 0.4)):
        m.emass(e, rho)
    m.mass(3, 0.2)
    m.mass(5, 0.1)
    m.mass(21, 0.05)
    m.force(3, 0.5, -0.2)
    m.force(5, 0.0, 1.0)
    m.force(31, 0.3)
    m.estiff(103, 2.0)
    m.edampp(103, 0.1)
    if spring:
        m.plhinge(104, 22, 42)
        m.rlse(104, 1)
        m.estiff(104, 1.5)
        m.edampp(104, 0.3)
    m.gravity(1.0, -G)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-12)
    m.timestep(4, 0.4)
    return m


def plbeamnl_chain():
    """Two rigid PLBEAMNL links, the second hinged by its own DYNX rotation (no PLHINGE)."""
    m = spacar.Model()
    m.x(2, 0.8, 0.3)
    m.x(3, 1.5, -0.2)
    m.plbeamnl(1, 1, 11, 2, 12)
    m.plbeamnl(2, 2, 21, 3, 22)
    m.fix(1)
    m.dynx(11, 1)
    m.dynx(21, 1)
    m.emass(1, 1.0)
    m.emass(2, 0.5)
    m.mass(3, 0.2)
    m.gravity(0.0, -G)
    m.epskin(1e-12)
    m.timestep(1, 0.1)
    return m


def planar_held_hinge():
    """A 2-link chain whose second hinge is not a DOF (its rotation held fixed)."""
    m = models.planar_chain(1)
    m.x(3, 2.0, 0.0)
    m.plbeam(2, 2, 21, 3, 22)
    m.plhinge(9, models.END + 1, 21)
    m.emass(2, 1.0)
    return m


def position_dof():
    """A pendulum whose DOF is the x coordinate of its tip (DYNX on an XY node)."""
    m = spacar.Model()
    m.x(2, 0.6, -0.8)
    m.plbeam(1, 1, 11, 2, 12)
    m.fix(1)
    m.dynx(2, 1)
    m.emass(1, 1.0)
    m.gravity(0.0, -G)
    return m


def truss_brace():
    """A pendulum braced by a PLTRUSS (an element the recursive path does not take)."""
    m = models.planar_chain(1)
    m.x(5, 0.5, -0.5)
    m.pltruss(9, 2, 5)
    m.fix(5)
    m.rlse(9, 1)
    return m


def _box(mass, a, b, c, rng):
    """A full inertia tensor: a box turned by a random rotation."""
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return Q @ (mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])) @ Q.T


def spatial_branched_tree(loads=True, seed=5):
    """A trunk hinged to a rotated ground, two branches hinged at its tip about different axes (one
    hinge points from the child to the parent, one body is two beams rigidly joined at a shared
    LAMBDA node), a grandchild on one branch at an offset point; EMASS with rotary inertia, point
    masses, full inertia tensors on LAMBDA nodes, a hinge spring-damper, gravity off the axes;
    ``loads``: TORQUEL on two bodies and FORCE on two points."""
    rng = np.random.default_rng(seed)
    m = spacar.Model()
    for node, p in {1: (0.1, -0.2, 0.3), 2: (0.5, 0.1, 0.8), 3: (0.9, 0.6, 0.7), 4: (0.3, 0.5, 1.2),
                    5: (0.1, 0.9, 1.3), 6: (1.2, 0.4, 1.1), 7: (1.0, 0.3, 0.2)}.items():
        m.xyz(node, *p)
    m.beam(1, 1, 11, 2, 12, 0.0, 0.0, 1.0)
    m.beam(2, 2, 21, 3, 22, 0.0, 1.0, 0.0)
    m.beam(3, 2, 31, 4, 32, 1.0, 0.0, 0.0)
    m.beam(4, 4, 32, 5, 42, 0.0, 0.0, 1.0)     # rigidly joined to beam 3 (LAMBDA node 32)
    m.beam(5, 3, 51, 6, 52, 1.0, 1.0, 0.0)     # the grandchild, hinged at node 3 of beam 2
    m.beam(6, 6, 52, 7, 62, 0.0, 1.0, 1.0)     # its second beam: node 7 is an offset point
    m.hinge(101, 100, 11, 0.3, -0.5, 0.8)
    m.hinge(102, 12, 21, 1.0, 0.2, -0.1)
    m.hinge(103, 31, 12, -0.2, 1.0, 0.4)       # from the child to the parent
    m.hinge(104, 22, 51, 0.1, 0.3, 1.0)
    for h in (101, 102, 103, 104):
        m.dyne(h, 1)
    m.fix(1)
    m.fix(100)
    m.lambda_(100, math.cos(0.2), *(math.sin(0.2) * np.array([0.6, 0.0, 0.8])))
    for e in range(1, 7):
        m.emass(e, 0.5 + rng.random(), 1e-3, 2e-3, 3e-3)
    m.mass(3, 0.2)
    m.mass(5, 0.1)
    m.mass(7, 0.3)
    for node, mass in ((21, 0.4), (32, 0.3), (52, 0.6)):
        J = _box(mass, *(0.1 + 0.2 * rng.random(3)), rng)
        m.mass(node, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
    m.estiff(103, 2.0)
    m.edampp(103, 0.1)
    if loads:
        m.torquel(21, 0.2, -0.1, 0.3)
        m.torquel(52, -0.1, 0.05, 0.2)
        m.force(5, 0.5, -0.2, 0.1)
        m.force(7, 0.0, 0.3, -0.4)
    m.gravity(1.0, -2.0, -G)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-13)
    m.timestep(3, 0.3)
    return m


def random_tree(n, seed, loads=True):
    """n bodies hung at random from the ground or an earlier body, at its end point or at an
    offset point of a second beam rigidly joined to it; hinges about random axes pointing either
    way, some with springs and dampers; random masses, inertia tensors and gravity; ``loads``:
    random TORQUEL and FORCE."""
    rng = np.random.default_rng(seed)
    m = spacar.Model()
    m.xyz(1, *rng.normal(size=3) * 0.1)
    points = {0: [1]}  # body → its points where children may hang (the ground: node 1)
    position = {1: np.array(m.nodes[1].x)}
    for i in range(1, n + 1):
        parent = int(rng.integers(0, i))
        pin = int(rng.choice(points[parent]))
        end, offset = 100 + i, 300 + i
        position[end] = position[pin] + rng.normal(size=3) * 0.4
        position[offset] = position[end] + rng.normal(size=3) * 0.2
        m.xyz(end, *position[end])
        m.xyz(offset, *position[offset])
        m.beam(i, pin, 1000 + i, end, 2000 + i, *rng.normal(size=3))
        m.beam(500 + i, end, 2000 + i, offset, 3000 + i, *rng.normal(size=3))  # rigidly joined
        parent_lambda = 10 if parent == 0 else 2000 + parent
        ends = (parent_lambda, 1000 + i) if rng.random() < 0.5 else (1000 + i, parent_lambda)
        m.hinge(700 + i, *ends, *rng.normal(size=3))
        m.dyne(700 + i, 1)
        m.emass(i, 0.5 + rng.random(), *(1e-3 * rng.random(3)))
        m.mass(offset, 0.1 + 0.2 * rng.random())
        J = _box(0.2 + 0.3 * rng.random(), *(0.1 + 0.2 * rng.random(3)), rng)
        m.mass(2000 + i, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2])
        torque, force = 0.2 * rng.normal(size=3), 0.3 * rng.normal(size=3)
        if loads:
            m.torquel(3000 + i, *torque)
            m.force(offset, *force)
        if rng.random() < 0.5:
            m.estiff(700 + i, rng.random())
            m.edampp(700 + i, 0.1 * rng.random())
        points[i] = [end, offset]
    m.fix(1)
    m.fix(10)
    m.gravity(*rng.normal(size=3) * 5.0)
    m.epskin(1e-13)
    return m


def spherical_joint():
    """A chain whose second link hangs from a shared node without a hinge (DYNX on its Euler
    parameters)."""
    return models.spatial_chain(2, seed=4, joints="spherical")


def rsur():
    from support.spatial_models import rssr_model

    model = rssr_model(coupler="beam", dynamic=True)
    model.epskin(1e-14)
    return model


def rsur_urdf_loop(name):
    """tests/data/<name> read with the RSUR's loop beside it: the coupler end a ball joint on the
    crank, the rocker's, the cross's and the coupler's joints passive."""
    import warnings

    from support.paths import DATA

    ball = {"parent": "crank", "child": "coupler", "xyz": (0.2, 0.0, 0.0), "type": "spherical"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # joint limits
        return spacar.from_urdf(DATA / name, loops=[ball], dependent=["rocker", "cross", "coupler"])


def urdf_rsur():
    """The RSUR of rsur() as a URDF tree with its loop closed by a ball joint beside it
    (tests/api/test_urdf_loops.py)."""
    model = rsur_urdf_loop("rsur_loop.urdf")
    model.ed(1, 1, 1.5)
    model.epskin(1e-14)
    return model


def urdf_rsup_pendulum():
    """The URDF RSUR with its rocker a sliding joint (a passive BEARING) and a pendulum hanging from
    the coupler (a second DOF), closed by a ball joint beside the URDF; gravity off the axes, springs
    and dampers on hinges (passive and DOF), FORCE and TORQUEL on bodies."""
    m = rsur_urdf_loop("rsup_pendulum_loop.urdf")
    m.gravity(0.5, -1.0, -9.81)
    for e, (k, d) in zip((3, 4, 1, 5), ((2.0, 0.3), (0.7, 0.1), (3.5, 0.4), (1.2, 0.05))):
        m.estiff(e, k)
        m.edampp(e, d)
    for node, f in zip((12, 21, 23), ((0.4, -0.3, 0.2), (-0.5, 0.1, 0.6), (0.2, 0.7, -0.4))):
        m.force(node, *f)
    for node, t in zip((10, 11, 4), ((0.1, -0.2, 0.05), (-0.15, 0.1, 0.2), (0.05, 0.25, -0.1))):
        m.torquel(node, *t)
    m.epskin(1e-14)
    return m


def four_bar_links():
    """The links of spacar.compare.models.four_bar without a DOF: crank PLBEAM 1 (1 → 2, BETA 11,
    12), coupler 2 (2 → 3), rocker 3 (4 → 3), nodes 1 and 4 fixed, EMASS, a MASS at node 3."""
    m = spacar.Model()
    m.plbeam(1, 1, 11, 2, 12)
    m.plbeam(2, 2, 21, 3, 22)
    m.plbeam(3, 4, 31, 3, 32)
    for node, xy in ((1, (0.0, 0.0)), (2, (0.0, 1.0)), (3, (2.0, 1.5)), (4, (2.5, 0.0))):
        m.x(node, *xy)
    m.fix(1)
    m.fix(4)
    for e, r in ((1, 1.0), (2, 1.5), (3, 1.2)):
        m.emass(e, r)
    m.mass(3, 0.3)
    return m


def five_bar():
    """A planar five-bar of 2 DOFs (the rotations of its two cranks, DYNX on BETA 11 and 41): ground
    pivots at nodes 1 and 4, cranks 1 (1 → 2) and 4 (4 → 5), couplers 2 (2 → 3) and 3 (5 → 3) closing
    the loop at node 3 (their rotations passive); EMASS, a MASS at node 3, gravity."""
    m = spacar.Model()
    m.plbeam(1, 1, 11, 2, 12)
    m.plbeam(2, 2, 21, 3, 22)
    m.plbeam(3, 5, 31, 3, 32)
    m.plbeam(4, 4, 41, 5, 42)
    for node, xy in ((1, (0.0, 0.0)), (2, (0.0, 1.0)), (3, (1.5, 1.8)), (5, (3.0, 1.0)), (4, (3.0, 0.0))):
        m.x(node, *xy)
    m.fix(1)
    m.fix(4)
    m.dynx(11, 1)
    m.dynx(41, 1)
    for e, r in ((1, 1.0), (2, 1.5), (3, 1.2), (4, 0.8)):
        m.emass(e, r)
    m.mass(3, 0.3)
    m.gravity(0.0, -9.81)
    m.epskin(1e-14)
    return m


def six_bar():
    """A planar six-bar of two loops (Watt type: the four-bar of four_bar_links and a dyad from its
    coupler–rocker joint, node 3, to a third ground pivot, node 6): 1 DOF (the crank, DYNX on BETA
    11), 4 passive rotations; EMASS, MASSes at nodes 3 and 5, gravity."""
    m = four_bar_links()
    m.plbeam(4, 3, 41, 5, 42)
    m.plbeam(5, 6, 51, 5, 52)
    m.x(5, 3.5, 2.2)
    m.x(6, 4.5, 0.3)
    m.fix(6)
    m.dynx(11, 1)
    m.emass(4, 0.7)
    m.emass(5, 0.9)
    m.mass(5, 0.2)
    m.gravity(0.0, -9.81)
    m.epskin(1e-14)
    return m


def reversed_hinged_four_bar():
    """The four-bar turned by a DYNE PLHINGE that points from the crank to the ground (its angle
    the negative of the crank's rotation), a released sprung and damped PLHINGE from rocker to
    coupler, FORCE on the coupler."""
    m = four_bar_links()
    m.plhinge(101, 11, 100)
    m.dyne(101, 1)
    m.fix(100)
    m.ed(101, 1, -1.5)
    m.plhinge(102, 32, 22)
    m.rlse(102, 1)
    m.estiff(102, 2.0)
    m.edampp(102, 0.1)
    m.mass(32, 0.05)
    m.force(2, 0.4, -0.2)
    m.gravity(0.0, -9.81)
    m.epskin(1e-14)
    return m


def hinged_four_bar():
    """A planar four-bar whose crank is turned by a DYNE PLHINGE from the ground's BETA node (a
    spring and a damper on it) and whose coupler and rocker are joined by a released PLHINGE with a
    spring: the loop closes at the coupler–rocker pin, the coupler's and rocker's rotations are
    passive. The geometry of spacar.compare.models.four_bar, a MASS with rotary inertia on the
    rocker's end, FORCE on the coupler."""
    m = four_bar_links()
    m.plhinge(101, 100, 11)
    m.dyne(101, 1)
    m.estiff(101, 4.0)
    m.edampp(101, 0.3)
    m.plhinge(102, 22, 32)
    m.rlse(102, 1)
    m.estiff(102, 2.0)
    m.fix(100)
    m.mass(32, 0.05)
    m.force(2, 0.4, -0.2)
    m.ed(101, 1, 1.5)
    m.gravity(0.0, -9.81)
    m.epskin(1e-14)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.timestep(5, 0.5)
    return m


def seven_bar(dof=1, last=7):
    """The spatial 7R loop of spacar.compare.models.seven_r_loop at tight tolerances, hinge `dof`
    its DOF (4: in the middle of the loop, which the tree must cut elsewhere), cut at hinge `last`
    (7: to the ground; 4: between two moving links)."""
    m = models.seven_r_loop(eps=1e-10, epskin=1e-14, dof=dof, last=last)
    m.timestep(5, 0.5)
    return m


def four_bar_driven_between_links():
    """The four-bar driven by a DYNE PLHINGE between the crank and the coupler (their relative
    angle the DOF): the crank's and the rocker's rotations are passive, the coupler hangs from the
    crank by the DOF hinge."""
    m = four_bar_links()
    m.plhinge(101, 12, 21)
    m.dyne(101, 1)
    m.ed(101, 1, 1.0)
    m.gravity(0.3, -9.81)
    m.epskin(1e-14)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.timestep(5, 0.5)
    return m


def rocker_driven_four_bar():
    """The four-bar of spacar.compare.models.four_bar with its rocker's rotation as the DOF: the
    crank and the coupler straighten (a fold of the loop) at a rocker angle of about −0.4006."""
    m = four_bar_links()
    m.dynx(31, 1)
    m.gravity(0.3, -9.81)
    m.epskin(1e-14)
    return m


def rsur_sprung_cut():
    """The RSUR with a HINGE between nodes 12 and 17 whose three deformations are released and
    sprung: it closes a loop (a cut) and has a law, which a cut cannot carry."""
    m = rsur()
    m.hinge(9, 12, 17, 0.0, 0.0, 1.0)
    m.rlse(9)
    m.estiff(9, 5.0)
    m.edampp(9, 0.5)
    return m


def spatial_held_hinge():
    """A chain whose second hinge is held (e1 fixed): the two links are one body."""
    m = models.spatial_chain(1, seed=1)
    m.xyz(3, 2.0, 0.5, 0.0)
    m.beam(2, 2, 21, 3, 22, 0.0, 0.0, 1.0)
    m.hinge(9, models.END + 1, 21, 0.0, 1.0, 0.0)
    m.emass(2, 1.0)
    return m


def flexible_beam():
    from support.spatial_models import cantilever

    return cantilever(2)


def lambda_force():
    m = models.spatial_chain(2, seed=1)
    m.force(models.START + 1, 0.0, 0.1, 0.0, 0.0)
    return m


def planar_massless_chain():
    return models.planar_chain(2, rho_a=0.0, tip_mass=0.0)


def spatial_massless_chain():
    """Two links on parallel hinges, only the first with mass."""
    model = spacar.Model()
    model.xyz(1, 0.0, 0.0, 0.0)
    model.xyz(2, 1.0, 0.0, 0.0)
    model.xyz(3, 2.0, 0.0, 0.0)
    model.beam(1, 1, 11, 2, 12, 0.0, 1.0, 0.0)
    model.beam(2, 2, 21, 3, 22, 0.0, 1.0, 0.0)
    model.hinge(3, 10, 11, 0.0, 0.0, 1.0)
    model.hinge(4, 12, 21, 0.0, 0.0, 1.0)
    model.dyne(3, 1)
    model.dyne(4, 1)
    model.fix(1)
    model.fix(10)
    model.emass(1, 1.0)
    return model


def urdf(path):
    """A robot read by spacar.from_urdf (joints at one origin, sliding joints, bodies without a
    beam: tests/data/wrist.urdf), at tight tolerances, nothing left out reported."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = spacar.from_urdf(path)
    m.epsint(1e-10)
    m.epsind(1e-10)
    m.epskin(1e-13)
    m.timestep(4, 0.4)
    return m
