"""spacar.Rollout: many initial states integrated with one set-up, against spacar.simulate from
each state (the same integration, so to rounding) and against Pinocchio's ABA integrated by
SciPy (an independent reference)."""
import numpy as np
import pytest

import spacar
from spacar.compare import models

EXAMPLE = "examples/slidercrank.dat"


def _dof_elements(roll):
    """The element of each DOF of a model whose DOFs are HINGE rotations ("e(k,1) HINGE")."""
    out = []
    for label in roll.dof_labels:
        assert label.startswith("e(") and label.endswith("HINGE")
        out.append(int(label[2:label.index(",")]))
    return out


def _simulated_from(model, roll, q0, qd0, **kw):
    """spacar.simulate of a copy of the model started at (q0, qd0)."""
    m = model.copy()
    for k, q, qd in zip(_dof_elements(roll), q0, qd0):
        m.e(k, 1, q)
        m.ed(k, 1, qd)
    return spacar.simulate(m, **kw)


@pytest.fixture(scope="module")
def chain():
    return models.spatial_chain(6, seed=6, t_end=0.3, n_out=6, eps=1e-8, epskin=1e-11)


def test_rollout_of_the_initial_state_is_the_block(chain):
    roll = spacar.Rollout(chain)
    res = roll(coordinates=True)
    ref = spacar.simulate(chain.copy())
    assert res.stats["path"] == "tree" == ref.stats["path"]
    np.testing.assert_allclose(res.t, ref.t, rtol=0, atol=1e-15)
    for a, b in ((res.q, ref.q), (res.qd, ref.qd), (res.x, ref.x)):
        assert a.shape == b.shape
        assert np.abs(a - b).max() <= 1e-12 * max(1.0, np.abs(b).max())
    assert res.stats["rhs_evaluations"][0] == ref.stats["rhs_evaluations"]
    assert res.dof_labels == ref.dof_labels


def test_a_batch_equals_a_block_from_each_state(chain):
    roll = spacar.Rollout(chain)
    rng = np.random.default_rng(1)
    base = roll()
    q0 = base.q[0] + 0.2 * rng.standard_normal((4, roll.n_dof))
    qd0 = 0.5 * rng.standard_normal((4, roll.n_dof))
    res = roll(q0, qd0, t=np.linspace(0.0, 0.3, 7))
    assert res.q.shape == res.qd.shape == (4, 7, roll.n_dof)
    for s in range(4):
        ref = _simulated_from(chain, roll, q0[s], qd0[s])
        assert np.abs(res.q[s] - ref.q).max() < 1e-12
        assert np.abs(res.qd[s] - ref.qd).max() < 1e-11
    # the set-up is kept: the same batch again gives the same numbers
    again = roll(q0, qd0, t=np.linspace(0.0, 0.3, 7))
    assert np.array_equal(again.q, res.q)


def test_against_pinocchio_aba_integrated_by_scipy(chain):
    pytest.importorskip("pinocchio")
    from scipy.integrate import solve_ivp

    from spacar.compare import pinocchio as sp

    model = models.spatial_chain(6, seed=6, t_end=0.5, n_out=5, eps=1e-11, epskin=1e-13)
    roll = spacar.Rollout(model)
    rng = np.random.default_rng(2)
    q0 = roll().q[0] + 0.3 * rng.standard_normal((3, roll.n_dof))
    qd0 = rng.standard_normal((3, roll.n_dof))
    t = np.linspace(0.0, 0.5, 6)
    res = roll(q0, qd0, t=t)
    f = sp.build(model).rhs()
    for s in range(3):
        ref = solve_ivp(f, (0.0, 0.5), np.concatenate((q0[s], qd0[s])), method="DOP853", t_eval=t,
                        rtol=1e-13, atol=1e-15)
        assert np.abs(res.q[s] - ref.y[:6].T).max() < 1e-8
        assert np.abs(res.qd[s] - ref.y[6:].T).max() < 1e-7


def test_general_path_and_closed_loop():
    model = spacar.read(EXAMPLE)
    roll = spacar.Rollout(model)
    res = roll(coordinates=True)
    ref = spacar.simulate(model.copy())
    assert res.stats["path"] == ref.stats["path"] != "tree"
    assert np.abs(res.q - ref.q).max() < 1e-12
    assert np.abs(res.qd - ref.qd).max() < 1e-10
    assert np.abs(res.x - ref.x).max() < 1e-12
    # Without the coordinates no state is solved at the output times, where a block's next
    # Newton iteration would start: the same solution to the tolerances (EPSINT 1e-3, EPSKIN 1e-5).
    plain = roll()
    assert np.abs(plain.q - ref.q).max() < 1e-5
    # a batch of rates (the manual's slider-crank: a flexible coupler whose bending deformations
    # are the DOFs, the crank an input): each row as if rolled out alone
    qd0 = np.array([plain.qd[0] + 0.01, plain.qd[0]])
    both = roll(qd0=qd0)
    assert both.q.shape == (2, len(ref.t), 4)
    assert np.array_equal(both.q[1], plain.q)
    assert np.array_equal(both.q[0], roll(qd0=qd0[0]).q)
    assert np.abs(both.q[0] - plain.q).max() > 1e-6


def test_forced_general_path_equals_the_tree(chain):
    tree = spacar.Rollout(chain)(t=[0.0, 0.1, 0.3])
    general = spacar.Rollout(chain, recursive=False)(t=[0.0, 0.1, 0.3])
    assert general.stats["path"] != "tree"
    assert np.abs(tree.q - general.q).max() < 1e-6  # two integrations at EPSINT 1e-8


def test_the_model_is_not_changed(chain):
    m = chain.copy()
    before = spacar.dump(m)
    spacar.Rollout(m)(np.zeros((2, 6)))
    assert spacar.dump(m) == before


@pytest.mark.parametrize("call, message", [
    (lambda r: r(np.zeros(5)), "one per DOF"),
    (lambda r: r(np.zeros((3, 6)), np.zeros((2, 6))), "same number of states"),
    (lambda r: r(t=[0.0, 0.2, 0.1]), r"must increase \(time 2 = 0.1 follows 0.2\)"),
    (lambda r: r(t=[0.0, np.inf]), "output time 1 is not finite"),
    (lambda r: r(t=[]), "no output times"),
    (lambda r: r(np.full(6, np.nan)), "finite"),
    (lambda r: r(coordinates=1), "True or False"),
])
def test_bad_requests_are_refused(chain, call, message):
    with pytest.raises(spacar.InputError, match=message):
        call(spacar.Rollout(chain))


def test_options_are_checked(chain):
    with pytest.raises(spacar.InputError, match="'generalized_alpha' only"):
        spacar.Rollout(chain, fixed_step=1e-3)
    with pytest.raises(spacar.InputError, match="method must be"):
        spacar.Rollout(chain, method="euler")
    with pytest.raises(spacar.InputError, match="no degrees of freedom"):
        spacar.Rollout(spacar.read_string("PLBEAM 1 1 2 3 4\nX 3 1 0\nFIX 1\nFIX 2\nFIX 3\nFIX 4\nEND\nEND\n"))


@pytest.mark.filterwarnings("ignore:.*(joint limits|collision)")
def test_a_tumbling_floating_base_keeps_its_dofs():
    """Solo12 thrown spinning (6 rad/s) for 2 s: past the half turn the run exchanges the dependent
    Euler parameter; the rollout still records the DOFs it started with (x, λ1, λ2, λ3, joints),
    equal to simulate's coordinates, and the next state of the batch starts in the first partition."""
    from test_urdf import solo12_tumbling

    model = solo12_tumbling()
    roll = spacar.Rollout(model)
    assert roll.dof_labels[:6] == ["x(1,1)", "x(1,2)", "x(1,3)", "x(2,2)", "x(2,3)", "x(2,4)"]
    ref = spacar.simulate(model.copy())
    assert ref.node(2).x[:, 0].min() < 0.0  # past the half turn: λ0 is no longer the dependent one
    res = roll(coordinates=True)
    assert res.stats["path"] == "tree"
    cols = [roll.coordinate_labels.index((1, i)) for i in (1, 2, 3)] + \
        [roll.coordinate_labels.index((2, i)) for i in (2, 3, 4)]
    # recorded with λ0 ≥ 0: the opposite Euler parameters where the run's λ0 went negative
    sign = np.where(ref.node(2).x[:, :1] < 0.0, -1.0, 1.0) * np.array([1, 1, 1, 1, 1, 1])
    sign[:, :3] = 1.0
    assert np.abs(res.q[:, :6] - sign * ref.x[:, cols]).max() < 1e-12
    assert np.abs(res.qd[:, :6] - sign * ref.xd[:, cols]).max() < 1e-11
    assert np.abs(res.q[:, 6:] - ref.q[:, 6:]).max() < 1e-12
    assert np.abs(res.x - ref.x).max() < 1e-12
    # a batch: the tumbling state, then one at rest, which starts in the first partition again
    q0 = np.repeat(res.q[:1], 2, axis=0)
    qd0 = np.array([res.qd[0], np.zeros(roll.n_dof)])
    batch = roll(q0, qd0)
    assert np.array_equal(batch.q[0], res.q)
    assert np.array_equal(batch.q[1], roll(q0[1], qd0[1]).q)


def test_a_failure_names_the_state_and_keeps_the_states_before(chain):
    roll = spacar.Rollout(chain)
    q0 = np.repeat(roll().q[:1], 3, axis=0)
    with pytest.raises(spacar.TimeLimitError) as info:
        roll(q0, t=np.linspace(0.0, 300.0, 3), time_limit=0.05)
    assert "rollout, state" in str(info.value)
    partial = info.value.results
    assert isinstance(partial, spacar.RolloutResults)
    assert partial.q.shape[1:] == (3, 6)


def test_generalized_alpha_on_a_flexible_arm():
    """A flexible model with the options of generalized-α: the rollout equals simulate's block."""
    model = spacar.read("examples/flexible_arm.dat")
    kw = dict(method="generalized_alpha", fixed_step=1e-4)
    res = spacar.Rollout(model, **kw)()
    ref = spacar.simulate(model.copy(), **kw)
    assert np.abs(res.q - ref.q).max() < 1e-12
    assert np.abs(res.qd - ref.qd).max() < 1e-9


def test_threads_give_the_same_states(chain):
    """A batch split over threads (each its own compiled copy) gives the states of one thread;
    a failure in the second part is numbered in the whole batch, the states before it kept."""
    one, two = spacar.Rollout(chain, threads=1), spacar.Rollout(chain, threads=2)
    rng = np.random.default_rng(3)
    q0 = one().q[0] + 0.2 * rng.standard_normal((6, one.n_dof))
    qd0 = rng.standard_normal((6, one.n_dof))
    a, b = one(q0, qd0), two(q0, qd0)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.qd, b.qd)
    assert np.array_equal(a.stats["rhs_evaluations"], b.stats["rhs_evaluations"])
    qd0[4] = 1e200  # its right-hand side overflows
    with pytest.raises(spacar.IntegrationError, match="rollout, state 4") as info:
        two(q0, qd0)
    assert np.array_equal(info.value.results.q, a.q[:4])
    with pytest.raises(spacar.InputError, match="threads"):
        spacar.Rollout(chain, threads=0)


def test_later_changes_of_the_model_are_not_seen(chain):
    m = chain.copy()
    roll = spacar.Rollout(m, threads=2)
    before = roll(np.zeros(6)).q  # one state: one simulation
    m.gravity(0.0, 0.0, -100.0)
    after = roll(np.zeros((4, 6))).q  # two parts: the second simulation is compiled now
    assert np.array_equal(after[0], before) and np.array_equal(after[-1], before)


@pytest.mark.filterwarnings("ignore:.*(joint limits|collision)")
def test_floating_base_states_restart_in_the_same_orientation():
    """Past the exchange of the dependent Euler parameter λ0 goes negative: the state is recorded
    with the opposite Euler parameters (the same orientation), so that a rollout from a recorded
    state continues the same motion; a batch whose first state ends back in its first partition
    (two exchanges) leaves the next state as if rolled out alone."""
    from test_urdf import solo12_tumbling

    model = solo12_tumbling()
    roll = spacar.Rollout(model)
    res = roll(coordinates=True)
    k = 7
    lam = res.x[k, [roll.coordinate_labels.index((2, i)) for i in range(1, 5)]]
    assert lam[0] < 0.0  # past the half turn
    again = roll(res.q[k], res.qd[k], t=res.t[k:], coordinates=True)
    assert np.abs(again.x[0] - res.x[k]).max() > 1.0  # λ → −λ: the same orientation, other parameters
    points = [c for c, (n, _) in enumerate(roll.coordinate_labels) if model.nodes[n].kind.name.upper() == "XYZ"]
    assert np.abs(again.x[:, points] - res.x[k:, points]).max() < 1e-7  # every point where it was
    assert np.abs(again.q - res.q[k:]).max() < 1e-7
    rng = np.random.default_rng(5)
    other = res.q[0] + 0.05 * rng.standard_normal(roll.n_dof)
    for t_end in (2.5, 2.0):  # ends in the first partition again, or in another
        t = np.linspace(0.0, t_end, 6)
        batch = roll(np.array([res.q[0], other]), np.array([res.qd[0], np.zeros(roll.n_dof)]), t=t)
        assert np.array_equal(batch.q[1], roll(other, np.zeros(roll.n_dof), t=t).q)


def test_threads_see_one_model():
    """Every thread's simulation prepares its own copy of the model (the first END normalizes the
    Euler parameters, which is not exactly idempotent: preparing a prepared copy again can move
    some by an ulp): chains whose bodies' reference orientation is a random unit quaternion give
    the same states on one thread or two."""
    for seed in range(10):
        model = models.spatial_chain(4, seed=seed, t_end=0.2, n_out=2, eps=1e-8, epskin=1e-11)
        lam = np.random.default_rng(seed).standard_normal(4)
        lambdas = [n for n, node in model.nodes.items() if node.kind.name.upper() == "LAMBDA"]
        for n in lambdas:
            model.x(n, *(lam / np.linalg.norm(lam)))
        one, two = spacar.Rollout(model, threads=1), spacar.Rollout(model, threads=2)
        q0 = one().q[0] + 0.1 * np.random.default_rng(seed).standard_normal((4, one.n_dof))
        assert np.array_equal(one(q0).q, two(q0).q), seed


def test_single_time_then_run_keeps_the_tree(chain):
    roll = spacar.Rollout(chain)
    assert roll(t=[0.0]).stats["path"] == "tree"
    assert roll().stats["path"] == "tree"


def test_batches_with_coordinates_and_empty_batches(chain):
    roll = spacar.Rollout(chain, threads=2)
    res = roll(np.zeros((3, 6)), coordinates=True)
    assert res.x.shape == (3, 2 + 5, len(roll.coordinate_labels))
    empty = roll(np.zeros((0, 6)), coordinates=True)
    assert empty.q.shape == (0, 7, 6) and empty.x.shape == (0, 7, len(roll.coordinate_labels))
