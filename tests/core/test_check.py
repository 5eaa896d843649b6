"""Solvability diagnosis of the constraints (`spacar check`, `model.check()`; issue #5,
formulation.md §2.3).

* over-constrained mechanisms with all deformations rigid: a planar four-bar whose rocker is
  welded to the coupler (immobile), a parallelogram with a redundant middle crank (mobile only
  thanks to its geometry), and the spatial four-bar of BEAMs and parallel HINGEs (the classic
  over-constraint by 3): the check names the redundant deformations; releasing the named ones
  makes the model run, with the motion of the closed-form / planar mechanism;
* under-constrained models (a four-bar without a driver, a spatial column free to twist): the
  check names the undetermined coordinates; fixing or driving the named one makes it run;
* the structured fields and the text of `spacar check`, and the KinematicsError of `spacar run`.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import spacar
from spacar.cli import main
from support.paths import EXAMPLES

EXAMPLE = EXAMPLES / "slidercrank.dat"

# Four-bar: ground pivots (0, 0) and (2, 0), crank (0, 0)–(0, 1), coupler (0, 1)–(2, 1.2),
# rocker (2, 0)–(2, 1.2); the crank turns at 1 rad/s from β2 = 0.
A0, B0 = np.array([0.0, 0.0]), np.array([2.0, 0.0])
CRANK, COUPLER, ROCKER = 1.0, math.hypot(2.0, 0.2), 1.2

FOURBAR = """\
PLBEAM 1 1 2 3 4
PLBEAM 2 3 5 6 7
PLBEAM 3 8 9 6 {rocker_rotation}
X 3 0.0 1.0
X 6 2.0 1.2
X 8 2.0 0.0
FIX 1
FIX 8
{drive}
EPSKIN 1e-12
TIMESTEP 4 1.0
END
"""
DRIVE = "INPUTX 2 1\nXD 2 1 1.0"


def fourbar(rocker_rotation=10, drive=DRIVE):
    return spacar.read_string(FOURBAR.format(rocker_rotation=rocker_rotation, drive=drive))


def fourbar_closed_form(theta):
    """Crank pin A and coupler–rocker pin B of the four-bar at crank angle θ (rotation of the
    crank from its initial direction +y), B on the branch of the initial geometry."""
    A = A0 + CRANK * np.array([-math.sin(theta), math.cos(theta)])
    d = B0 - A
    dist = np.linalg.norm(d)
    a = (COUPLER**2 - ROCKER**2 + dist**2) / (2 * dist)
    h = math.sqrt(COUPLER**2 - a**2)
    mid = A + a * d / dist
    perp = np.array([-d[1], d[0]]) / dist
    return A, mid + h * perp  # the initial B = (2, 1.2) is on this side


def test_pinned_fourbar_passes_the_check():
    check = fourbar().check()
    d = check.diagnosis
    assert d.ok and d.redundant == [] and d.undetermined == []
    assert (d.n_constraints, d.n_calculable, d.rank) == (9, 9, 9)
    assert "the constraints determine the calculable coordinates" in str(check)
    res = fourbar().run()
    for k, t in enumerate(res.t):
        A, B = fourbar_closed_form(t)
        assert np.allclose(res.node(3).x[k], A, atol=1e-10) and np.allclose(res.node(6).x[k], B, atol=1e-10)


def test_welded_fourbar_names_the_redundant_deformation(tmp_path, capsys):
    """The rocker shares the coupler's end rotation node 7 (a weld instead of a pin): 9 rigid
    deformations for 8 calculable coordinates. The check names the rocker's end bending (3, 3);
    `spacar run` fails with the same advice; after RLSE 3 3 the model is the pinned four-bar."""
    model = fourbar(rocker_rotation=7)
    d = model.check().diagnosis
    assert not d.ok
    assert (d.n_constraints, d.n_calculable, d.rank) == (9, 8, 8)
    assert d.redundant == [(3, 3)] and d.undetermined == []
    assert "over-constrained by 1" in d.text and "RLSE 3 3" in d.text

    path = tmp_path / "welded.dat"
    path.write_text(FOURBAR.format(rocker_rotation=7, drive=DRIVE))
    assert main(["check", str(path)]) == 1   # problems reported: a gate fails
    out = capsys.readouterr().out
    assert all(line.startswith("*") for line in out.splitlines())
    assert "* nodal coordinates: 13 (4 fixed, 1 input, 8 calculable)" in out
    assert "over-constrained by 1" in out and "RLSE 3 3" in out
    assert main(["run", str(path)]) == 1
    err = capsys.readouterr().err
    assert "KinematicsError" in err and "RLSE 3 3" in err
    with pytest.raises(spacar.KinematicsError, match="RLSE 3 3"):
        fourbar(rocker_rotation=7).run()

    model.rlse(*d.redundant[0])
    assert model.check().diagnosis.ok
    res = model.run()
    pinned = fourbar().run()
    assert np.allclose(res.node(6).x, pinned.node(6).x, rtol=0, atol=1e-12)
    assert np.allclose(res.node(3).x, pinned.node(3).x, rtol=0, atol=1e-12)


def parallelogram():
    """Cranks from the fixed pivots (0, 0), (1, 0), (2, 0) to (0, 1), (1, 1), (2, 1); the coupler
    of two PLBEAMs welded at (1, 1) (shared rotation node 14), pinned to the three cranks. The
    middle crank is redundant: 15 rigid deformations for 14 calculable coordinates."""
    m = spacar.Model()
    m.plbeam(1, 1, 2, 3, 4)
    m.plbeam(2, 5, 6, 7, 8)
    m.plbeam(3, 9, 10, 11, 12)
    m.plbeam(4, 3, 13, 7, 14)
    m.plbeam(5, 7, 14, 11, 15)
    for node, xy in ((3, (0, 1)), (5, (1, 0)), (7, (1, 1)), (9, (2, 0)), (11, (2, 1))):
        m.x(node, *xy)
    m.fix(1)
    m.fix(5)
    m.fix(9)
    m.inputx(2, 1)
    m.xd(2, 1, 1.0)
    m.epskin(1e-12)
    m.timestep(8, 3.0)
    return m


def test_parallelogram_with_redundant_crank():
    model = parallelogram()
    d = model.check().diagnosis
    assert (d.n_constraints, d.n_calculable, d.rank) == (15, 14, 14)
    assert len(d.redundant) == 1 and d.undetermined == []
    # The dependent combination (the self-stress of the loop) contains the three crank lengths.
    assert all(f"element {e} (PLBEAM) deformation 1" in d.text for e in (1, 2, 3))
    with pytest.raises(spacar.KinematicsError):
        parallelogram().run()
    model.rlse(*d.redundant[0])
    assert model.check().diagnosis.ok
    res = model.run()
    # The coupler translates: every crank pin moves like the first one.
    t = res.t
    offset = np.column_stack([-np.sin(t), np.cos(t)])
    for node, pivot in ((3, (0, 0)), (7, (1, 0)), (11, (2, 0))):
        assert np.allclose(res.node(node).x, np.array(pivot) + offset, rtol=0, atol=1e-10)


def spatial_fourbar():
    """The four-bar of rigid BEAMs (an orientation node at each end) joined by HINGEs about z:
    ground → crank (INPUTE, 1 rad/s), crank → coupler, coupler → rocker, ground → rocker, the
    last three with e1 released. Classic over-constraint: 33 equations for 30 coordinates."""
    m = spacar.Model()
    m.beam(1, 1, 2, 3, 10, 0.0, 0.0, 1.0)
    m.beam(2, 3, 11, 5, 12, 0.0, 0.0, 1.0)
    m.beam(3, 6, 7, 5, 13, 0.0, 0.0, 1.0)
    m.x(3, 0.0, 1.0, 0.0)
    m.x(5, 2.0, 1.2, 0.0)
    m.x(6, 2.0, 0.0, 0.0)
    m.hinge(4, 8, 2, 0.0, 0.0, 1.0)
    m.hinge(5, 10, 11, 0.0, 0.0, 1.0)
    m.hinge(6, 12, 13, 0.0, 0.0, 1.0)
    m.hinge(7, 9, 7, 0.0, 0.0, 1.0)
    for node in (1, 6, 8, 9):
        m.fix(node)
    m.inpute(4, 1)
    m.ed(4, 1, 1.0)
    for hinge in (5, 6, 7):
        m.rlse(hinge, 1)
    m.epskin(1e-12)
    m.timestep(4, 1.0)
    return m


def test_spatial_fourbar_with_parallel_hinges():
    """The check names three redundant deformations (hinge misalignments); releasing exactly
    those makes the model run, in the plane, with the planar four-bar's motion."""
    model = spatial_fourbar()
    d = model.check().diagnosis
    assert (d.n_constraints, d.n_calculable, d.rank) == (33, 30, 30)
    assert len(d.redundant) == 3 and d.undetermined == []
    assert "over-constrained by 3" in d.text
    with pytest.raises(spacar.KinematicsError, match="over-constrained by 3"):
        spatial_fourbar().run()
    for e, i in d.redundant:
        assert model.elements[e].type_name == "HINGE" and i in (2, 3)
        model.rlse(e, i)
    assert model.check().diagnosis.ok
    res = model.run()
    for k, t in enumerate(res.t):
        A, B = fourbar_closed_form(t)
        assert np.allclose(res.node(3).x[k], [*A, 0.0], atol=1e-10)
        assert np.allclose(res.node(5).x[k], [*B, 0.0], atol=1e-10)


def test_fourbar_without_driver_names_the_undetermined_coordinate():
    """Without the INPUTX the crank angle is calculable too: 9 equations for 10 coordinates.
    The check names one coordinate of the free motion; driving it makes the model run, and the
    free motion it reports involves the crank angle β2."""
    model = fourbar(drive="")
    d = model.check().diagnosis
    assert (d.n_constraints, d.n_calculable, d.rank) == (9, 10, 9)
    assert d.redundant == [] and len(d.undetermined) == 1
    assert "under-constrained by 1" in d.text and "free motion:" in d.text
    assert "node 2 component 1" in d.text
    with pytest.raises(spacar.KinematicsError, match="under-constrained by 1"):
        fourbar(drive="").run()
    node, comp = d.undetermined[0]
    free_motion = d.text.split("free motion:")[1]
    assert f"node {node} component {comp} " in free_motion
    fixed = fourbar(drive=f"FIX {node} {comp}")
    assert fixed.check().diagnosis.ok
    fixed.run()  # a structure now: kinematic analysis at the output times
    driven = fourbar(drive=f"INPUTX {node} {comp}\nXD {node} {comp} 0.1")
    assert driven.check().diagnosis.ok
    res = driven.run()
    assert np.ptp(res.node(3).x[:, 0]) > 1e-3  # the mechanism moves


def test_spatial_column_free_to_twist_names_a_rotation():
    """BEAMNL column pinned at both ends (positions only): the twist about its axis is free.
    The check names the λ1 of an orientation node; fixing it gives the Euler load."""
    n = 2

    def column(extra=None):
        m = spacar.Model()
        for k in range(n):
            m.beamnl(k + 1, 2 * k + 1, 2 * k + 2, 2 * k + 3, 2 * k + 4, 0.0, 1.0, 0.0)
            m.x(2 * k + 3, (k + 1) / n, 0.0, 0.0)
            m.estiff(k + 1, 0.0, 1.0, 1.0, 1.0)
            m.emass(k + 1, 1.0)
            m.dyne(k + 1, 3, 4, 5, 6)
        m.fix(1)
        m.fix(2 * n + 1, 2, 3)
        m.force(2 * n + 1, -1.0, 0.0, 0.0)
        if extra:
            m.fix(*extra)
        return m

    d = column().check().diagnosis
    assert len(d.undetermined) == 1 and d.redundant == []
    node, comp = d.undetermined[0]
    assert node % 2 == 0 and comp == 2  # λ1 of an orientation node: rotation about x
    assert all(f"node {k} component 2" in d.text for k in range(2, 2 * n + 3, 2))
    with pytest.raises(spacar.KinematicsError, match="under-constrained"):
        spacar.linearize(column())
    fixed = column((node, comp))
    assert fixed.check().diagnosis.ok
    mu = spacar.linearize(fixed).buckling_factors()
    assert abs(mu[0] - 9.9438468) < 1e-6 and abs(mu[1] - 9.9438468) < 1e-6


def test_manual_slider_crank_is_well_posed():
    check = spacar.read(EXAMPLE).check()
    assert check.diagnosis.ok
    assert check.summary.degrees_of_freedom == 4
    assert (check.diagnosis.n_constraints, check.diagnosis.n_calculable) == (9, 9)
    text = str(check)
    assert "degrees of freedom: 4" in text and "9 constraint equations" in text and "rank 9" in text


def test_check_does_not_change_the_model():
    model = fourbar(rocker_rotation=7)
    before = model.dump(digits=17)
    model.check()
    assert model.dump(digits=17) == before and not model.core.frozen


def test_a_redundant_dynx_is_named_with_its_line(tmp_path, capsys):
    """Issue 41: a DYNX on a coordinate the loop already determines (node 3's x of the crank-rocker)
    over-constrains it by one. Besides a deformation to release, the check names the prescribed
    coordinates whose freeing removes the redundancy — the crank's input and the new DYNX — and
    the latest line that prescribed one of them, with its place in the file."""
    text = (EXAMPLES / "fourbar_coupler.dat").read_text().replace("\nEND", "\nDYNX 3 1\nEND", 1)
    path = tmp_path / "fourbar_dynx.dat"
    path.write_text(text)
    d = spacar.check(spacar.read(path)).diagnosis
    assert not d.ok and d.rank == d.n_calculable == d.n_constraints - 1
    assert (3, 1) in d.determined and len(d.redundant) == 1
    line = text[: text.index("DYNX 3 1")].count("\n") + 1
    assert f"the latest line that prescribed one of them: DYNX 3 1 ({path}, line {line}, keyword DYNX)" in d.text
    assert "DYNX 3 1   (node 3 component 1, a degree of freedom)" in d.text
    # Removing that line (x of node 3 calculable again) gives the model that passes.
    assert spacar.check(spacar.read(EXAMPLES / "fourbar_coupler.dat")).ok
    # Built in Python: the same diagnosis, without a file line.
    m = spacar.read(EXAMPLES / "fourbar_coupler.dat")
    m.dynx(3, 1)
    d = spacar.check(m).diagnosis
    assert (3, 1) in d.determined and "the latest line that prescribed one of them: DYNX 3 1;" in d.text


def test_the_latest_prescribing_line_is_the_last_given():
    from spacar.check import _latest_prescribed

    m = spacar.read(EXAMPLES / "fourbar_coupler.dat")
    for n, c in ((3, 1), (6, 1), (3, 1)):
        m.dynx(n, c)
    assert "DYNX 3 1;" in _latest_prescribed(m, [(3, 1), (6, 1)])
    m.dynx(6)                                        # the whole node, after the component lines
    assert "DYNX 6;" in _latest_prescribed(m, [(3, 1), (6, 1)])
