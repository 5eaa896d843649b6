"""spacar.Results (issue #7): arrays over the output times, lookup by node and element numbers and
by keyword names, to_pandas, save/load (.npz), pickling, concatenation of blocks, the geometry
attached for drawing, and the progress bar over simulated time.

References are independent of the lookup code: the states passed to the on_output callback
(recorded by the test itself), column positions counted from the input file, and round trips.
"""
import pickle
import subprocess
import sys

import numpy as np
import pytest

import spacar
from support.paths import EXAMPLES
from support.planar_models import compressed_cantilever

EXAMPLE = EXAMPLES / "slidercrank.dat"

# Nodes of the manual's slider-crank and their kinds (manual §5.7): XY 1, 3, 6, 8; BETA 2, 4, 5, 7, 9.
NODE_SIZES = {1: 2, 2: 1, 3: 2, 4: 1, 5: 1, 6: 2, 7: 1, 8: 2, 9: 1}


@pytest.fixture(scope="module")
def run():
    """The manual's example with every on_output state recorded."""
    states = []
    model = spacar.read(EXAMPLE)
    res = spacar.simulate(model, on_output=lambda k, s: states.append((k, {n: np.array(v) for n, v in s.items()})))
    return model, res, states


def test_arrays_have_one_row_per_output_time(run):
    _, res, states = run
    assert len(res) == 101
    np.testing.assert_allclose(res.t, np.linspace(0.0, 5.0, 101), rtol=0, atol=1e-14)
    assert res.x.shape == res.xd.shape == res.xdd.shape == res.reaction.shape == (101, 13)
    assert res.e.shape == res.ed.shape == res.edd.shape == res.sigma.shape == (101, 9)
    assert [k for k, _ in states] == list(range(101))
    for name in ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        np.testing.assert_array_equal(np.array([s[name] for _, s in states]), getattr(res, name))
    assert res.reactions is res.reaction


def test_node_lookup_follows_ascending_node_and_component_order(run):
    _, res, _ = run
    col = 0
    for n, size in NODE_SIZES.items():
        node = res.node(n)
        assert node.node == n
        for name in ("x", "xd", "xdd", "reaction"):
            np.testing.assert_array_equal(getattr(node, name), getattr(res, name)[:, col:col + size])
        for i in range(1, size + 1):
            assert res.coordinate_index(n, i) == col + i - 1
            np.testing.assert_array_equal(res.coordinate(n, i), res.x[:, col + i - 1])
            np.testing.assert_array_equal(res.coordinate(n, i, "XDD"), res.xdd[:, col + i - 1])
        col += size
    assert col == res.x.shape[1]
    assert res.node_columns == {n: list(range(sum(list(NODE_SIZES.values())[:j]), sum(list(NODE_SIZES.values())[:j + 1])))
                                for j, n in enumerate(NODE_SIZES)}


def test_element_lookup(run):
    _, res, _ = run
    for el in (1, 2, 3):
        er = res.element(el)
        cols = slice(3 * (el - 1), 3 * el)
        for name in ("e", "ed", "edd", "sigma"):
            np.testing.assert_array_equal(getattr(er, name), getattr(res, name)[:, cols])
    np.testing.assert_array_equal(res.deformation(2, 2), res.e[:, 4])
    np.testing.assert_array_equal(res.deformation(3, 3, "ED"), res.ed[:, 8])
    np.testing.assert_array_equal(res.stress(2, 1), res.sigma[:, 3])
    # The manual's dump at t = 5 s: E 2 2 = 2.673E-03 (within the 0.5 % of formulation.md §10.5)
    assert res.deformation(2, 2)[-1] == pytest.approx(2.673e-3, rel=5e-3)


@pytest.mark.parametrize("key, array, col", [
    (("X", 8, 1), "x", 10), (("XD", 2, 1), "xd", 2), (("xdd", 3, 2), "xdd", 4),
    (("E", 2, 2), "e", 4), (("ED", 2, 3), "ed", 5), (("EDD", 3, 2), "edd", 7),
    (("SIGMA", 2, 1), "sigma", 3), (("s", 1, 1), "sigma", 0), (("REACTION", 8, 2), "reaction", 11),
    (("r", 1, 1), "reaction", 0),
    ("x(8,1)", "x", 10), ("e(2,2)", "e", 4), ("s(2,1)", "sigma", 3), ("r(8,2)", "reaction", 11),
    ("XD 2 1", "xd", 2), ("EDD 3 2", "edd", 7),
])
def test_lookup_by_keyword_names_and_labels(run, key, array, col):
    _, res, _ = run
    expected = getattr(res, array)[:, col]
    if isinstance(key, tuple):
        np.testing.assert_array_equal(res[key], expected)
        np.testing.assert_array_equal(res.get(*key), expected)
    else:
        np.testing.assert_array_equal(res[key], expected)
        np.testing.assert_array_equal(res.get(key), expected)
    assert res.column(key) == (array, col)


def test_the_crank_velocity_is_the_input_rate(run):
    _, res, _ = run
    np.testing.assert_array_equal(res["XD", 2, 1], 1.5)   # XD 2 1 1.5 of the input
    np.testing.assert_array_equal(res["t"], res.t)


def test_labels(run):
    _, res, _ = run
    assert res.labels("x")[:4] == ["x(1,1)", "x(1,2)", "x(2,1)", "x(3,1)"]
    assert res.labels("SIGMA")[-1] == "s(3,3)"
    assert res.labels("reaction")[-1] == "r(9,1)"
    assert spacar.Results.label(("XD", 2, 1)) == "xd(2,1)"
    assert spacar.Results.label("sigma(2,1)") == "s(2,1)"
    assert spacar.Results.describe("e(2,2)") == "e(2,2): deformation, element 2, deformation 2"
    assert spacar.Results.describe(("X", 8, 1)) == "x(8,1): position, node 8, component 1"
    assert res.time_index(2.52) == 50


@pytest.mark.parametrize("call, text", [
    (lambda r: r.node(99), "no node 99"),
    (lambda r: r.element(7), "no element 7"),
    (lambda r: r.coordinate(2, 2), "node 2 has no component 2"),
    (lambda r: r.deformation(1, 4), "element 1 has no deformation 4"),
    (lambda r: r["Q", 1, 1], "unknown quantity 'Q'"),
    (lambda r: r["x[8,1]"], "cannot read 'x[8,1]'"),
    (lambda r: r.coordinate(2, 1, "e"), "deformation quantity"),
    (lambda r: r.deformation(2, 1, "xd"), "coordinate quantity"),
])
def test_lookup_errors(run, call, text):
    _, res, _ = run
    with pytest.raises(spacar.InputError, match=text.replace("[", r"\[").replace("(", r"\(")):
        call(res)


def test_geometry_describes_the_model(run):
    model, res, _ = run
    g = res.geometry
    assert isinstance(g, spacar.Geometry)
    assert g.node_kinds == {1: "XY", 2: "BETA", 3: "XY", 4: "BETA", 5: "BETA", 6: "XY", 7: "BETA", 8: "XY", 9: "BETA"}
    assert [(e.id, e.type, e.nodes) for e in g.elements] == [
        (1, "PLBEAM", (1, 2, 3, 4)), (2, "PLBEAM", (3, 5, 6, 7)), (3, "PLBEAM", (6, 7, 8, 9))]
    assert [e.l0 for e in g.elements] == pytest.approx([0.15, 0.15, 0.15])
    assert [e.lgeomy for e in g.elements] == [(0.0,), (0.0,), (0.0,)]
    assert g.coordinate_classes[1] == ("fixed", "fixed")
    assert g.coordinate_classes[2] == ("input",)
    assert g.coordinate_classes[8] == ("calculable", "fixed")
    assert g.masses == {8: (0.033375,)}
    assert not g.spatial
    assert g.anchors() == {2: 1, 4: 3, 5: 3, 7: 6, 9: 8}
    assert g.joints() == [1, 3, 8]   # crank pivot, crank pin, slider pin (6 joins two beams rigidly)
    assert spacar.Geometry.from_dict(g.to_dict()) == g


def test_geometry_is_that_of_the_model_at_the_run():
    """res.geometry is built on first use (from a copy of the model taken at the run), so later
    changes of the model before the next block do not reach it."""
    model = spacar.read(EXAMPLE)
    res = spacar.simulate(model)
    expected = spacar.Geometry.from_model(model)
    assert res._geometry_source is not None          # not built yet
    model.mass(8, 0.5)                                # element, class and mass changes before the next block
    model.lgeomy(3, 0.01)
    model.dynx(2, 1)
    model.timestep(5, 0.05)
    second = spacar.simulate(model)
    assert spacar.Geometry.from_model(model) != expected
    assert second.geometry == spacar.Geometry.from_model(model)
    assert second.geometry.coordinate_classes[2] == ("dynamic",) and second.geometry.masses == {8: (0.5,)}
    again = pickle.loads(pickle.dumps(res))           # pickling a results whose geometry is not built yet
    assert res.geometry == expected and again.geometry == expected
    assert res.geometry is res.geometry               # built once
    assert res.geometry.coordinate_classes[2] == ("input",) and res.geometry.elements[2].lgeomy == (0.0,)
    res.geometry = None
    assert res.geometry is None and res.supported_columns() == list(range(13))


def test_supported_columns_are_the_fixed_and_input_coordinates(run):
    _, res, _ = run
    # FIX 1 (both), INPUTX 2 1, FIX 8 2 in the input file
    assert [res.coordinate_labels[c] for c in res.supported_columns()] == [(1, 1), (1, 2), (2, 1), (8, 2)]
    others = [c for c in range(13) if c not in res.supported_columns()]
    assert np.all(res.reaction[:, others] == 0.0)


def test_to_pandas(run):
    pd = pytest.importorskip("pandas")
    _, res, _ = run
    df = res.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert df.index.name == "t"
    np.testing.assert_array_equal(df.index.to_numpy(), res.t)
    assert list(df.columns[:13]) == res.labels("x")
    np.testing.assert_array_equal(df["x(8,1)"].to_numpy(), res.node(8).x[:, 0])
    np.testing.assert_array_equal(df["edd(3,3)"].to_numpy(), res.edd[:, 8])
    np.testing.assert_array_equal(df["s(2,1)"].to_numpy(), res.sigma[:, 3])
    assert [c for c in df.columns if c.startswith("r(")] == ["r(1,1)", "r(1,2)", "r(2,1)", "r(8,2)"]
    assert df.shape == (101, 4 * 13 - 9 + 4 * 9)
    small = res.to_pandas(["E"])
    assert list(small.columns) == res.labels("e")


def _assert_same(a, b):
    for name in ("t", "x", "xd", "xdd", "e", "ed", "edd", "sigma", "reaction"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.coordinate_labels == b.coordinate_labels
    assert a.deformation_labels == b.deformation_labels
    assert a.stats == b.stats
    assert a.geometry == b.geometry
    assert a.settings_linear == b.settings_linear


def test_save_and_load(run, tmp_path):
    _, res, _ = run
    path = tmp_path / "run.npz"
    res.save(path)
    back = spacar.Results.load(path)
    _assert_same(res, back)
    np.testing.assert_array_equal(back.node(8).x, res.node(8).x)
    assert back.linearizations == []


def test_load_rejects_other_npz_files(tmp_path):
    path = tmp_path / "other.npz"
    np.savez(path, meta=np.array('{"format": "else"}'))
    with pytest.raises(spacar.InputError, match="not a spacar results file"):
        spacar.Results.load(path)


def test_pickle(run):
    _, res, _ = run
    _assert_same(res, pickle.loads(pickle.dumps(res)))


def cantilever(n=4):
    m = compressed_cantilever(n)
    m.timestep(2, 0.1)
    return m


def test_save_and_load_keep_the_linearizations(tmp_path):
    res = spacar.simulate(cantilever())
    assert len(res.linearizations) == 3
    res.save(tmp_path / "lin.npz")
    back = spacar.Results.load(tmp_path / "lin.npz")
    _assert_same(res, back)
    for a, b in zip(res.linearizations, back.linearizations):
        assert a.t == b.t and a.z_labels == b.z_labels and a.n_line == b.n_line
        for name in ("M0", "C0", "D0", "K0", "N0", "G0", "r0", "DF", "DFe"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
        np.testing.assert_array_equal(a.eigenfrequencies(), b.eigenfrequencies())
        np.testing.assert_array_equal(a.buckling_factors(), b.buckling_factors())
    # Euler buckling of a cantilever, P = π²/4 (formulation.md §10.4: 4 PLBEAMNL, 2.4674819)
    assert back.linearizations[0].buckling_factors()[0] == pytest.approx(2.4674819, rel=1e-7)
    again = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(again.linearizations[1].M0, res.linearizations[1].M0)


def test_concatenate_blocks():
    model = spacar.read(EXAMPLE)
    first = spacar.simulate(model)
    model.timestep(50, 2.5)
    second = spacar.simulate(model)
    both = spacar.Results.concatenate([first, second])
    assert len(both) == 152
    assert both.t[100] == both.t[101] == 5.0          # the block boundary appears twice
    np.testing.assert_array_equal(both.x[:101], first.x)
    np.testing.assert_array_equal(both.x[101:], second.x)
    np.testing.assert_allclose(both.x[101], both.x[100], rtol=0, atol=1e-12)  # continuous at the boundary
    assert both.stats["rhs_evaluations"] == first.stats["rhs_evaluations"] + second.stats["rhs_evaluations"]
    assert both.stats["recursive"] is False  # the slider-crank's flexible rod: the general path
    assert both.geometry == second.geometry
    other = spacar.simulate(cantilever(2))
    with pytest.raises(spacar.InputError, match="different models"):
        spacar.Results.concatenate([first, other])
    with pytest.raises(spacar.InputError, match="at least one"):
        spacar.Results.concatenate([])


def test_import_spacar_does_not_import_the_optional_packages():
    code = ("import sys, spacar; heavy = [m for m in ('matplotlib', 'pandas', 'tqdm', 'scipy') if m in sys.modules]; "
            "print(','.join(heavy))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""



def test_save_and_load_keep_the_kinematic_coordinates_of_a_linearization(tmp_path):
    # Issue 18: y_labels, Kk, AK0 and BK0 were not saved, so that a loaded nonholonomic
    # linearization (the bicycle: LINEAR 1, one output time) had no eigenvalues or state matrix.
    from spacar.linearize import MATRICES

    res = spacar.simulate(spacar.read(EXAMPLES / "bicycle.dat"), progress=False)
    res.save(tmp_path / "bicycle.npz")
    a, b = res.linearizations[0], spacar.Results.load(tmp_path / "bicycle.npz").linearizations[0]
    assert len(a.y_labels) == 4 and b.y_labels == a.y_labels
    for name in MATRICES:
        np.testing.assert_array_equal(getattr(b, name), getattr(a, name))
    np.testing.assert_array_equal(b.state_matrix(), a.state_matrix())
    np.testing.assert_array_equal(b.eigenvalues(), a.eigenvalues())
    for outputs in ("z", "x"):
        for p, q in zip(b.state_space(outputs), a.state_space(outputs)):
            np.testing.assert_array_equal(p, q)
