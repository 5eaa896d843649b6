"""The compiled System (cpp/src/model/system.cpp): the split of coordinates and deformations into
fixed, input, dynamic and calculable ones, checked by counting on the manual's slider-crank
(three PLBEAMs, 9 nodes: 13 nodal coordinates and 9 deformations, manual §6.1) and on models
built here."""
import spacar
from spacar import _core
from support.paths import EXAMPLES


def compiled(model):
    return _core.Simulation(model.core).system


def test_the_manual_slider_crank_is_split_as_its_input_says():
    s = compiled(spacar.read(EXAMPLES / "slidercrank.dat"))
    assert (s.nx, s.ne) == (13, 9)  # nodes 1, 3, 6, 8: x, y; nodes 2, 4, 5, 7, 9: β
    labels = [tuple(lbl) for lbl in s.coord_label]
    fixed = sorted(labels[g] for g in s.x_fixed)
    assert fixed == [(1, 1), (1, 2), (8, 2)]  # FIX 1, FIX 8 2
    assert [labels[g] for g in s.x_input] == [(2, 1)]  # INPUTX 2 1: the crank angle
    assert [tuple(s.def_label[k]) for k in s.e_dyn] == [(2, 2), (2, 3), (3, 2), (3, 3)]  # DYNE
    assert s.n_dof == 4 and list(s.x_dyn) == []
    # Every other coordinate is calculable, with as many position constraints (the rigid
    # deformations: all of element 1's, the elongations of 2 and 3) as calculable coordinates.
    assert len(s.x_calc) == s.nx - 3 - 1 == 9
    assert len(s.defs_P) == len(s.x_calc)


def test_dynx_makes_a_coordinate_a_degree_of_freedom():
    m = spacar.Model()
    m.pltruss(1, 1, 2)
    m.x(2, 1.0, 0.0)
    m.fix(1)
    m.dynx(2)
    m.mass(2, 1.0)
    s = compiled(m)
    labels = [tuple(lbl) for lbl in s.coord_label]
    assert [labels[g] for g in s.x_dyn] == [(2, 1), (2, 2)]
    # node 1 fixed, node 2's both coordinates DOFs: none is left to calculate
    assert s.n_dof == 2 and len(s.x_calc) == 0
