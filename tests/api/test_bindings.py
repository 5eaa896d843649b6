"""The bindings are generated from the core's field tables (model.hpp) and parse options once:
the pickled records and the properties list the same fields in the same order, and the entry
points that take an integration method refuse an unknown one alike."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from spacar import _core, _testing
from support.paths import EXAMPLES, ROOT

EXAMPLE = EXAMPLES / "slidercrank.dat"


def properties(cls):
    return [name for name, value in vars(cls).items() if isinstance(value, property)]


def test_the_pickled_records_hold_the_properties_in_their_order():
    model = spacar.read(EXAMPLE)
    core = model._core
    _, nodes, elements, settings, *_ = core.__getstate__()
    node, element = core.nodes[1], core.elements[1]
    node_fields = properties(_core.Node)
    assert len(nodes[0]) == len(node_fields)
    for name, stored in zip(node_fields, nodes[0]):
        value = getattr(node, name)
        assert stored == (int(value) if name == "kind" else [int(c) for c in value] if name == "cls" else value)
    element_fields = [n for n in properties(_core.Element) if n != "type_name"]
    assert len(elements[0]) == len(element_fields)
    for name, stored in zip(element_fields, elements[0]):
        value = getattr(element, name)
        if name == "type":
            assert stored == element.type_name
        elif name == "cls":
            assert stored == [int(c) for c in value]
        elif name == "kinematic_of":
            assert [list(v) for v in stored] == [list(v) for v in value]
        else:
            assert stored == value
    settings_fields = properties(_core.Settings)
    assert list(settings) == [getattr(core.settings, name) for name in settings_fields]


def test_both_entry_points_refuse_an_unknown_integration_method_alike():
    """One parser (integrator.hpp parse_method): the simulation and the integrator raise
    the same InputError, which is also a ValueError."""
    sim = _core.Simulation(spacar.read(EXAMPLE).core)
    errors = []
    for call in (lambda: sim.run(method="rk4"),
                 lambda: _testing.explicit_rk_solve(lambda t, y: y, 0.0, [1.0], 1.0, [1.0], 1e-6, 1e-6, method="rk4")):
        try:
            call()
        except Exception as err:  # noqa: BLE001 - the type is what is checked
            errors.append(err)
    assert len(errors) == 2
    assert [type(e) for e in errors] == [spacar.InputError, spacar.InputError]
    assert str(errors[0]) == str(errors[1]) == "unknown integration method 'rk4' (auto, dop853, dopri5, radau5, generalized_alpha)"
    assert isinstance(errors[0], ValueError)


def test_every_state_entry_point_checks_the_sizes_of_q_and_qd():
    """The checks are in the core, at the entry of each algorithm (simulate.hpp)."""
    import numpy as np
    import pytest

    sim = _core.Simulation(spacar.read(EXAMPLE).core)
    sim.assemble()
    n = sim.system.n_dof
    good, bad = np.zeros(n), np.zeros(n + 1)
    for name, args in (("evaluate", (0.0,)), ("solve_state", (0.0,)), ("move_to", (0.0,)), ("recursive_state", ())):
        for q, qd in ((bad, good), (good, bad)):
            with pytest.raises(spacar.InputError, match=rf"{name}\(\): q and qd must have one value per degree"):
                getattr(sim, name)(*args, q, qd)


def test_the_test_bindings_are_not_in_the_shipped_core():
    for name in ("element_kernel", "ElementKernel", "explicit_rk_solve", "dop853_solve", "SparseLU"):
        assert not hasattr(_core, name)
    assert callable(_testing.element_kernel) and callable(_testing.explicit_rk_solve)


def test_simulate_and_linearize_prepare_the_model_once(monkeypatch):
    """The core's Simulation prepares the model (the first END); the Python layer does not again."""
    calls = []
    monkeypatch.setattr(spacar.Model, "prepare", lambda self: calls.append(self))
    model = spacar.read(EXAMPLE)
    assert not model._core.frozen
    spacar.simulate(model)
    spacar.linearize(model)
    assert calls == [] and model._core.frozen


def test_the_lists_that_cross_into_python_come_from_the_core():
    """Issue 35: the output arrays, energy columns, run counters and run defaults are the core's
    tables; the Python tables keyed by them (quantities, MATASC files, saved files) cover exactly
    the core's output arrays."""
    from spacar.compare import models
    from spacar.energy import KEYS
    from spacar.io.matasc import STATE_FILES
    from spacar.results import _ARRAYS, _FLOAT_ARRAYS, QUANTITIES, STATE_ARRAYS
    from spacar.sweep import RESULT_ARRAYS

    names = [name for name, _, _ in _core.output_arrays]
    assert list(STATE_ARRAYS) == names and _ARRAYS == ("t", *names) and RESULT_ARRAYS == _ARRAYS
    assert set(QUANTITIES) == set(names) and {a for a, _ in STATE_FILES.values()} == set(names)
    for name, over, _ in _core.output_arrays:
        assert QUANTITIES[name][1] == over
        assert _FLOAT_ARRAYS[name] == ("nt", "ne" if over == "deformation" else "nx")
    assert KEYS == _core.energy_columns
    assert [k for k, _ in _core.run_counters][:4] == ["rhs_evaluations", "steps", "accepted", "rejected"]
    m = models.cantilever(2, t_end=0.01, n_out=2)
    res = spacar.simulate(m, method="dop853", progress=False)
    assert "jacobians" not in res.stats and "rhs_evaluations" in res.stats
    res = spacar.simulate(models.cantilever(2, t_end=0.01, n_out=2), method="radau5", progress=False)
    assert {"jacobians", "decompositions"} <= set(res.stats)


def test_the_package_does_not_import_the_test_bindings():
    """Issue 35: spacar (spacar.compare included) runs without spacar._testing."""
    for path in (ROOT / "python" / "spacar").rglob("*.py"):
        assert "_testing" not in path.read_text(encoding="utf-8"), path


def test_element_deformations_of_many_states_are_the_elongations():
    """`_core.element_deformations` (spacar.compare's map of a peer's states): a PLTRUSS's
    deformation is its length minus its reference length, one row per state."""
    rng = np.random.default_rng(7)
    x = rng.normal(size=(5, 4))
    e = _core.element_deformations("PLTRUSS", x, l0=2.0)
    np.testing.assert_allclose(e[:, 0], np.hypot(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]) - 2.0, rtol=1e-14)
    with pytest.raises(spacar.InputError, match="4 columns"):
        _core.element_deformations("PLTRUSS", x[:, :3])
    with pytest.raises(spacar.InputError, match="unknown element type"):
        _core.element_deformations("NOSUCH", x)
