"""State-space models of the linearized equations with physical inputs and outputs (issue 22):

    d/dt s = A s + B u,    y = C s + D u,    s = [δz; δy^k; δż]

in the minimal coordinates of :mod:`spacar.linearize` — z the degrees of freedom (and LINE
parameters), y^k the kinematic coordinates of nonholonomic constraints, no constraint states.
The inputs u are forces on nodal coordinates (INPUTF) and actuator stresses on deformations
(INPUTS); the outputs y are nodal coordinates (OUTX), deformations (OUTE), their rates (OUTXP,
OUTEP) and the stresses of elastic deformations (OUTS). They enter through the first-order transfer functions DF = ∂x/∂z and DFe = ∂e/∂z: a
force f on a coordinate does the virtual work f δx = f DF δz, so its generalized force is DFᵀ f;
a stress σ does σ δe on the deformation and loads the coordinates by −DFeᵀ σ (the sign of the
elements' own stresses: σ > 0 is tension).
"""
from __future__ import annotations

import math

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError, SingularMassError
from .linearize import Linearization, _count, _modal_basis, linearized_simulation, second_order_eigenvalues
from .model import NODE_SIGNALS, Model, Signal

INPUT_KEYWORDS = ("INPUTF", "INPUTS", "BASEX", "BASEXP", "BASEXPP")
OUTPUT_KEYWORDS = ("OUTX", "OUTXP", "OUTXPP", "OUTE", "OUTEP", "OUTS", "OUTR")
_NAMES = {"INPUTF": "f", "INPUTS": "sigma", "BASEX": "u", "BASEXP": "ud", "BASEXPP": "udd", "OUTX": "x",
          "OUTXP": "xd", "OUTXPP": "xdd", "OUTE": "e", "OUTEP": "ed", "OUTS": "sigma", "OUTR": "r"}
# The derivative of a support's motion that a base input prescribes (position, velocity, acceleration).
_BASE_ORDER = {"BASEX": 0, "BASEXP": 1, "BASEXPP": 2}
# The signals built on the nodal matrices of a state at rest (the supports' motion, accelerations
# and reactions): _build_base.
_AT_REST = ("BASEX", "BASEXP", "BASEXPP", "OUTXPP", "OUTR")


class StateSpace:
    """A linear time-invariant model ds/dt = A s + B u, y = C s + D u (NumPy arrays) with the
    labels of its states, inputs and outputs (``"x(2,1)"``: coordinate 1 of node 2, ``"xd(2,1)"``
    its rate, ``"e(3,2)"``/``"ed(3,2)"`` a deformation and its rate, ``"f(2,1)"`` a force input,
    ``"sigma(3,2)"`` a stress input or output). ``t`` is the time of the state linearized about and
    ``linearization`` the :class:`spacar.Linearization` it was built from. Time in seconds:
    poles in rad/s."""

    def __init__(self, A, B, C, D, state_labels, input_labels, output_labels, t=0.0, linearization=None,
                 second_order=None):
        """``second_order``: (M, Dm, K, Q) of the equations A and B come from, without kinematic
        coordinates; the frequency response then solves them directly."""
        self.A, self.B, self.C, self.D = (np.asarray(m, dtype=float) for m in (A, B, C, D))
        self._mdk = None if second_order is None else (*second_order, self.A.copy(), self.B.copy())
        self.state_labels = list(state_labels)
        self.input_labels = list(input_labels)
        self.output_labels = list(output_labels)
        self.t = float(t)
        self.linearization = linearization

    def poles(self) -> np.ndarray:
        """Eigenvalues of A in rad/s (complex), sorted by |Im| and then Re: the eigenvalues of
        :meth:`spacar.Linearization.eigenvalues`. While A is that of the second-order equations
        (no kinematic coordinates), from those in their undamped modes
        (:func:`spacar.linearize.second_order_eigenvalues`: the slow poles of a fine mesh keep
        their digits)."""
        second_order = self._second_order()
        lam = None if second_order is None else second_order_eigenvalues(*second_order[:3])
        if lam is None:
            lam = np.linalg.eigvals(self.A)
        return lam[np.lexsort((lam.real, np.abs(lam.imag)))]

    def frequency_response(self, freqs, unit: str = "Hz") -> np.ndarray:
        """The transfer matrix C (iω I − A)⁻¹ B + D at each frequency, complex, of shape
        (len(freqs), outputs, inputs). ``freqs`` in Hz (``unit="Hz"``, ω = 2π f) or in rad/s
        (``unit="rad/s"``)."""
        w = _frequencies(freqs, unit)
        out = np.empty((w.size, self.C.shape[0], self.B.shape[1]), dtype=complex)
        second_order = self._second_order()
        for j, wj in enumerate(w):
            try:
                with np.errstate(over="ignore", invalid="ignore"):  # an overflow is said below
                    out[j] = self._response(wj, second_order)
            except np.linalg.LinAlgError:
                raise InputError(f"frequency_response: ω = {wj:g} rad/s is a pole of the model (e.g. ω = 0 "
                                 "with a free rigid-body motion)") from None
            if not np.isfinite(out[j]).all():  # ω² times the model's matrices beyond double precision
                raise InputError(f"frequency_response: at ω = {wj:g} rad/s the response overflows double "
                                 "precision (ω² times the mass matrix); give lower frequencies")
        return out

    def _response(self, w, second_order):
        if second_order:
            # s = [δz; iω δz] with (K − ω² M + iω Dm) δz = Q u: a system half the size, without M⁻¹
            # (better conditioned for stiff models)
            M, Dm, K, Q = second_order
            X = np.linalg.solve(K - w**2 * M + 1j * w * Dm, Q)
            return self.C @ np.vstack([X, 1j * w * X]) + self.D
        return self.C @ np.linalg.solve(1j * w * np.eye(self.A.shape[0]) - self.A, self.B) + self.D

    def _second_order(self):
        """(M, Dm, K, Q) of M δz̈ + Dm δż + K δz = Q u when the model has no kinematic coordinates
        and A, B are still those built from them; None otherwise."""
        if self._mdk is None:
            return None
        *mdk, A, B = self._mdk
        return mdk if np.array_equal(A, self.A) and np.array_equal(B, self.B) else None

    def static_gain(self) -> np.ndarray:
        """−C A⁻¹ B + D (outputs × inputs): the static response per unit input; needs a
        non-singular A (no rigid-body motion, no free kinematic coordinates). Without kinematic
        coordinates it is C [K⁻¹ Q; 0] + D, from the stiffness directly."""
        second_order = self._second_order()
        try:
            if second_order:
                _, _, K, Q = second_order
                X = np.linalg.solve(K, Q)
                return self.C @ np.vstack([X, np.zeros_like(X)]) + self.D
            return -self.C @ np.linalg.solve(self.A, self.B) + self.D
        except np.linalg.LinAlgError:
            raise InputError("static_gain: A is singular (a free rigid-body motion or kinematic coordinate "
                             "has no static response)") from None

    def bode(self, freqs=None, unit: str = "Hz"):
        """A matplotlib figure with the magnitude (log scale) and phase (degrees) of every
        output/input pair over ``freqs`` (default: a decade below the slowest to a decade above
        the fastest pole). Returns the figure."""
        import matplotlib.pyplot as plt  # lazily: `import spacar` stays light

        if freqs is None:
            mag = np.abs(self.poles())
            mag = mag[mag > 1e-9 * max(mag.max(initial=0.0), 1.0)]
            lo, hi = (mag.min() / 10, mag.max() * 10) if mag.size else (0.1, 100.0)
            freqs = np.logspace(np.log10(lo), np.log10(hi), 500) / (1.0 if unit == "rad/s" else 2 * np.pi)
        w = _frequencies(freqs, unit)
        x = w / (2 * np.pi) if unit == "Hz" else w
        H = self.frequency_response(w, unit="rad/s")
        fig, (ax_mag, ax_phase) = plt.subplots(2, 1, sharex=True)
        for i, out in enumerate(self.output_labels):
            for j, inp in enumerate(self.input_labels):
                ax_mag.loglog(x, np.abs(H[:, i, j]), label=f"{out} / {inp}")
                ax_phase.semilogx(x, np.degrees(np.unwrap(np.angle(H[:, i, j]))))
        ax_mag.set_ylabel("magnitude")
        ax_phase.set_ylabel("phase [deg]")
        ax_phase.set_xlabel(f"frequency [{unit}]")
        if self.input_labels and self.output_labels:
            ax_mag.legend()
        return fig

    def to_scipy(self):
        """The model as a ``scipy.signal.StateSpace``."""
        import scipy.signal

        return scipy.signal.StateSpace(self.A, self.B, self.C, self.D)

    def to_control(self):
        """The model as a ``control.StateSpace`` of python-control (the optional extra
        ``spacar[control]``), with the labels as its signal names."""
        try:
            import control
        except ImportError:
            raise ImportError('to_control needs python-control: pip install control (from a clone of spacar: '
                              'pip install ".[control]")') from None
        return control.ss(self.A, self.B, self.C, self.D, states=self.state_labels,
                          inputs=self.input_labels, outputs=self.output_labels)

    def reduce(self, k: int, method: str = "modal") -> "StateSpace":
        """A model of ``k`` states (modal: ``k`` modes, 2k states) approximating this one.

        ``method="modal"``: the ``k`` lowest undamped modes of the second-order equations (no
        kinematic coordinates), their damping projected (Φᵀ C Φ), and the static response of the
        modes left out as the feedthrough, C_x (K⁻¹ − Φ Ω⁻² Φᵀ) Q: the static gain stays exact
        (as ``state_space(modes=k)`` on the nodal matrices, here from the dense model).

        ``method="balanced"``: balanced truncation (square-root method) to ``k`` states, for a
        stable model (every pole in the left half-plane: damping from EDAMPP, ``damping=`` or
        ``rayleigh=``); ``hankel_singular_values`` holds all of them and ``error_bound`` the
        H∞ bound 2 Σ_{i>k} σ_i of the error of the reduced model."""
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k:
            raise InputError(f"reduce: k must be a positive whole number, got {show(k)}")
        if method == "modal":
            return _modal_reduction(self, int(k))
        if method == "balanced":
            return _balanced_reduction(self, int(k))
        raise InputError(f"reduce: method must be 'modal' or 'balanced', got {show(method)}")

    def __repr__(self):
        return (f"<spacar.StateSpace at t = {self.t:g}: {len(self.state_labels)} states, "
                f"{len(self.input_labels)} inputs, {len(self.output_labels)} outputs>")


def _modal_reduction(ss: StateSpace, k: int) -> StateSpace:
    second_order = ss._second_order()
    if second_order is None:
        raise InputError("reduce(method='modal') needs the second-order equations (a model without kinematic "
                         "coordinates, A and B as built)")
    M, C, K, Q = second_order
    n = M.shape[0]
    if k > n:
        raise InputError(f"reduce: k = {k} modes of a model of {n} degrees of freedom")
    if not np.any(M):
        raise SingularMassError("reduce: the modes need masses: no node or element of the model carries mass")
    w2, phi = _mass_normalized_modes(M, K)
    w2, phi = w2[:k], phi[:, :k]
    if not np.all(w2 > 0):
        raise InputError("reduce(method='modal'): a kept mode has no stiffness (a rigid-body motion); the static "
                         "correction needs a supported model")
    Cz, Cv = ss.C[:, :n], ss.C[:, n:]
    Qm = phi.T @ Q
    damping = phi.T @ C @ phi
    A = np.block([[np.zeros((k, k)), np.eye(k)], [-np.diag(w2), -damping]])
    B = np.vstack([np.zeros((k, Q.shape[1])), Qm])
    static = np.linalg.solve(K, Q)
    D = ss.D + Cz @ (static - phi @ (Qm / w2[:, None]))
    states = [f"mode({i + 1})" for i in range(k)] + [f"moded({i + 1})" for i in range(k)]
    return StateSpace(A, B, np.hstack([Cz @ phi, Cv @ phi]), D, states, ss.input_labels, ss.output_labels, ss.t,
                      ss.linearization, (np.eye(k), damping, np.diag(w2), Qm))


def _balanced_reduction(ss: StateSpace, k: int) -> StateSpace:
    import scipy.linalg

    A, B, C = ss.A, ss.B, ss.C
    n = A.shape[0]
    if k > n:
        raise InputError(f"reduce: k = {k} states of a model of {n}")
    if not np.all(np.linalg.eigvals(A).real < 0):
        raise InputError("reduce(method='balanced') needs a stable model (every pole in the left half-plane): give "
                         "it damping (EDAMPP, state_space(damping=...) or rayleigh=...) and no rigid-body motion")
    Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    Wo = scipy.linalg.solve_continuous_lyapunov(A.T, -C.T @ C)
    Lc, Lo = _square_root(Wc), _square_root(Wo)          # W = L Lᵀ
    U, hsv, Vt = scipy.linalg.svd(Lo.T @ Lc)
    significant = int(np.sum(hsv > np.finfo(float).eps * hsv[0])) if hsv.size and hsv[0] > 0 else 0
    if k > significant:
        raise InputError(f"reduce(method='balanced'): only {significant} of the model's Hankel singular values are "
                         f"above ε σ1 (the others are states no input reaches or no output sees); reduce to at most "
                         f"{significant} states")
    scale = 1.0 / np.sqrt(hsv[:k])
    T = Lc @ Vt[:k].T * scale                               # n × k
    Ti = (U[:, :k] * scale).T @ Lo.T                        # k × n, Ti T = I
    reduced = StateSpace(Ti @ A @ T, Ti @ B, C @ T, ss.D, [f"balanced({i + 1})" for i in range(k)], ss.input_labels,
                         ss.output_labels, ss.t, ss.linearization)
    reduced.hankel_singular_values = hsv
    reduced.error_bound = 2.0 * float(np.sum(hsv[k:]))
    return reduced


def _square_root(W):
    """L with W = L Lᵀ for a symmetric positive semidefinite Gramian (the eigenvalues rounded
    below zero clipped)."""
    w, V = np.linalg.eigh(0.5 * (W + W.T))
    return V * np.sqrt(np.clip(w, 0.0, None))


def state_space(source, at=None, inputs=None, outputs=None, *, modes=None, damping=None, rayleigh=None,
                time_limit=None) -> StateSpace:
    """The state-space model of ``source`` linearized about a state.

    ``source``: a :class:`spacar.Model`; a :class:`spacar.Linearization`; or a
    :class:`spacar.Results` of a run with LINE or ``LINEAR 1``, whose linearization at the output
    time nearest to ``at`` (default the last) is taken. For a Model, ``at`` is None for the
    model's current state, ``(t, q, qd)`` as for :func:`spacar.linearize`, or ``(res, t)`` for
    the state of the results ``res`` at its output time nearest to t.
    ``inputs``/``outputs``: lists of ``(keyword, number, index)``, e.g. ``[("INPUTF", 2, 1)]``,
    ``[("OUTX", 2, 1), ("OUTXP", 2, 1)]``; default the model's INPUTF/INPUTS and
    OUTX/OUTXP/OUTE/OUTEP/OUTS lines in the order of their k.

    Rate outputs at a moving state include the convective term ∂(DF ż)/∂z, stress outputs need
    ∂σ/∂z and ∂σ/∂ż, and the outputs of a nonholonomic model their derivatives over its kinematic
    coordinates y^k: these come from central differences on the Model, for models without LINE
    parameters; otherwise they are refused.

    ``modes``: the number k of the lowest undamped modes to keep (None: all degrees of freedom).
    The model is then built on the sparse nodal matrices of a state at rest in static equilibrium
    (:func:`spacar.linearize`, docs/formulation.md §10), with no dense matrix of the model's size: the
    states are the modal coordinates and their rates (Φᵀ M Φ = I), A = [[0, I], [−Ω², −Φᵀ D Φ]],
    and the static response of the truncated modes, C (K⁻¹ − Φ Ω⁻² Φᵀ) F, is kept as the direct
    feedthrough D, so that the static gain stays exact (the residual flexibility of the modal
    truncation). For models of thousands of degrees of freedom; damping from EDAMPP.

    ``damping``: modal damping ratios ζ added to the element damping (EDAMPP), as SPACAR Light's
    relative damping: one value for every mode, or a sequence for the lowest modes in order
    (the others keep only the element damping). Mode i then gets the damping 2 ζ_i ω_i in its
    modal coordinate: C += M Φ diag(2 ζ ω) Φᵀ M with the undamped modes Φᵀ M Φ = I of
    (K0 + N0 + G0, M0). ``rayleigh=(α, β)``: C += α M0 + β (K0 + N0 + G0), a mode's ratio
    α/(2ω) + βω/2. Both need masses; they add to each other and to EDAMPP.

    ``time_limit``: wall-clock seconds the whole construction may take (linearization, the
    differences of the velocities, the modes), as for :func:`spacar.linearize`."""
    ratios = _damping_ratios(damping)
    alpha, beta = _rayleigh(rayleigh)
    with time_limited(time_limit, "in state_space"):
        ss, damped = _state_space(source, at, inputs, outputs, modes, (ratios, alpha, beta))
    if not damped and (ratios is not None or alpha or beta):
        ss = _add_damping(ss, ratios, alpha, beta)
    return ss


def _damping_ratios(damping):
    """None, or the modal damping ratios as an array (a scalar: every mode)."""
    if damping is None:
        return None
    try:
        ratios = np.array(damping, dtype=float)
    except (TypeError, ValueError, OverflowError):
        ratios = None
    if ratios is None or ratios.ndim > 1 or not np.isfinite(ratios).all() or (ratios < 0).any():
        raise InputError(f"state_space: damping must be a modal damping ratio ζ ≥ 0 or a sequence of them (lowest "
                         f"mode first), got {show(damping)}")
    return ratios


def _rayleigh(rayleigh):
    if rayleigh is None:
        return 0.0, 0.0
    try:
        alpha, beta = (float(v) for v in rayleigh)
    except (TypeError, ValueError, OverflowError):
        alpha = beta = math.nan
    if not (math.isfinite(alpha) and math.isfinite(beta) and alpha >= 0 and beta >= 0):
        raise InputError(f"state_space: rayleigh must be (α, β), two finite numbers ≥ 0, got {show(rayleigh)}")
    return alpha, beta


def _add_damping(ss: StateSpace, ratios, alpha: float, beta: float) -> StateSpace:
    """ss with the modal and Rayleigh damping in its second-order equations M δz̈ + C δż + K δz = Q u
    (the states [δz; δż] of the dense model, or the modal coordinates of modes=)."""
    second_order = ss._second_order()
    if second_order is None:
        raise InputError("state_space: damping= and rayleigh= need the second-order equations M δz̈ + C δż + K δz: "
                         "not a model with nonholonomic constraints")
    M, C, K, Q = second_order
    if not np.any(M):
        raise SingularMassError("state_space: damping= and rayleigh= need masses: no node or element of the model "
                                "carries mass")
    n = M.shape[0]
    C = C + _added_damping(M, K, ratios, alpha, beta)
    A = ss.A.copy()
    A[n:, n:] = -np.linalg.solve(M, C)
    return StateSpace(A, ss.B, ss.C, ss.D, ss.state_labels, ss.input_labels, ss.output_labels, ss.t,
                      ss.linearization, (M, C, K, Q))


def _added_damping(M, K, ratios, alpha: float, beta: float) -> np.ndarray:
    """The damping matrix of damping= and rayleigh=: α M + β K plus M Φ diag(2 ζ ω) Φᵀ M over the
    undamped modes Φᵀ M Φ = I (the modal ratios ζ, one for all or the lowest modes')."""
    extra = alpha * M + beta * K
    if ratios is None:
        return extra
    n = M.shape[0]
    w2, phi = _mass_normalized_modes(M, K)
    zeta = np.zeros(n)
    if ratios.ndim == 0:
        zeta[:] = ratios
    elif len(ratios) > n:
        raise InputError(f"state_space: damping gives {len(ratios)} modal ratios for {n} modes")
    else:
        zeta[:len(ratios)] = ratios
    Mphi = M @ phi
    return extra + Mphi @ np.diag(2.0 * zeta * np.sqrt(np.abs(w2))) @ Mphi.T


def _mass_normalized_modes(M, K):
    """(ω², Φ) of K φ = ω² M φ, sorted by |ω²|, with Φᵀ M Φ = I (linearize's modal basis). The modes
    of a symmetric problem only: a stiffness made unsymmetric by a moving state (N0) or follower
    loads has no such basis."""
    basis = _modal_basis(M, K)
    if basis is None:
        raise InputError("state_space: modal damping and the modal reduction need the symmetric undamped problem "
                         "(K0 + N0 + G0 symmetric, as at rest without follower loads); this stiffness is not "
                         "symmetric: use rayleigh= or EDAMPP, and reduce(method='balanced')")
    w2, phi = basis
    order = np.argsort(np.abs(w2))
    return w2[order], phi[:, order]


def _state_space(source, at, inputs, outputs, modes, extra_damping) -> tuple:
    """(the state space, whether the extra damping is in it already)."""
    if hasattr(source, "linearizations") and hasattr(source, "time_index"):  # a spacar.Results
        if not source.linearizations:
            raise InputError("state_space: these results have no linearizations (run with LINE or LINEAR 1), "
                             "or pass the Model with at=(res, t)")
        source, at = source.linearizations[source.time_index(source.t[-1] if at is None else at)], None
    if isinstance(source, Linearization):
        if at is not None:
            raise InputError("state_space: `at` applies to a Model; a Linearization is already at its state")
        if inputs is None or outputs is None:
            raise InputError("state_space of a Linearization needs inputs= and outputs= (it has no input lines)")
        lin, velocities = source, None
    elif isinstance(source, Model):
        inputs = _signals(source.state_space_inputs, "inputs") if inputs is None else inputs
        outputs = _signals(source.state_space_outputs, "outputs") if outputs is None else outputs
        lin, sim, state = linearized_simulation(source, _state(at))
        velocities = (sim, state)
    else:
        raise InputError(f"state_space: a spacar.Model, Linearization or Results, got {show(source)}")
    inputs = _checked(inputs, INPUT_KEYWORDS, "inputs")
    outputs = _checked(outputs, OUTPUT_KEYWORDS, "outputs")
    at_rest = [s for s in inputs + outputs if s.keyword in _AT_REST]
    if at_rest:
        if not isinstance(source, Model) or modes is not None:
            raise InputError(f"{_where(at_rest[0])}: the supports' motion, accelerations and reactions are built "
                             "from the Model at rest (no Linearization or Results source, no modes=)")
        return _build_base(lin, velocities[0], inputs, outputs, *extra_damping), True
    if modes is not None:
        return _build_modal(lin, inputs, outputs, modes), False
    return _build(lin, inputs, outputs, velocities), False


def _state(at):
    if at is None:
        return None
    if isinstance(at, tuple) and len(at) == 2 and hasattr(at[0], "time_index"):
        res, t = at
        k = res.time_index(t)
        return res.t[k], res.q[k], res.qd[k]
    return at


def _signals(table: dict, what: str) -> list:
    """The model's inputs or outputs in the order of k, which must run 1, 2, ... without gaps."""
    ks = sorted(table)
    if ks != list(range(1, len(ks) + 1)):
        missing = sorted(set(range(1, ks[-1] + 1)) - set(ks))
        raise InputError(f"state_space: the {what} must be numbered 1, 2, ... without gaps: "
                         f"{', '.join(map(str, ks))} are defined, {missing[0]} is missing")
    return [table[k] for k in ks]


def _checked(signals, keywords, what) -> list:
    if isinstance(signals, (str, bytes)) or not hasattr(signals, "__iter__"):
        raise InputError(f"state_space: {what} must be a list of (keyword, number, index), got {show(signals)}")
    out = []
    for s in signals:
        try:
            keyword, number, index = s[:3]
            keyword = str(keyword).upper()
            ok = keyword in keywords and all(isinstance(v, (int, np.integer)) and not isinstance(v, bool)
                                             for v in (number, index))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise InputError(f"state_space: each of the {what} must be (keyword, number, index) with the keyword "
                             f"one of {', '.join(keywords)}, got {show(s)}")
        out.append(Signal(keyword, int(number), int(index), getattr(s, "origin", "")))
    return out


def _where(sig: Signal) -> str:
    return sig.origin or f"{sig.keyword} {sig.number} {sig.index}"


def _row(lin: Linearization, sig: Signal) -> tuple:
    """(DF or DFe, the row of the signal's coordinate or deformation in it)."""
    on_node = sig.keyword in NODE_SIGNALS
    labels = lin.coordinate_labels if on_node else lin.deformation_labels
    key = (sig.number, sig.index)
    if key not in labels:
        what = "node {} has no coordinate {}" if on_node else "element {} has no deformation {}"
        raise InputError(f"{_where(sig)}: {what.format(*key)}")
    return (lin.DF if on_node else lin.DFe), labels.index(key)


def _build(lin: Linearization, inputs, outputs, velocities) -> StateSpace:
    n, k = lin.M0.shape[0], len(getattr(lin, "y_labels", []))
    z_names = [f"{kind}({a},{b})" for kind, a, b in lin.z_labels]
    # Generalized forces of the inputs (nz x m).
    for sig in outputs:   # each output named by a coordinate or deformation the model has
        _row(lin, sig)
    Q = np.zeros((n, len(inputs)))
    for j, sig in enumerate(inputs):
        T, r = _row(lin, sig)
        if not np.any(T[r]):
            raise InputError(f"{_where(sig)}: the input does no work on the degrees of freedom (a fixed or "
                             "input coordinate, or a deformation that is not DYNE, released or LINE)")
        Q[:, j] = T[r] if sig.keyword == "INPUTF" else -T[r]
    if not k:
        lin._require_mass("the state space")
        massless = _massless_directions(lin.M0)
        if massless is not None:
            return _build_condensed(lin, inputs, outputs, Q, _sensitivities(lin, outputs, velocities), *massless)
    A = lin.state_matrix()
    B = np.vstack([np.zeros((n + k, len(inputs))), np.linalg.solve(lin.M0, Q)])
    C = np.zeros((len(outputs), 2 * n + k))
    sens = _sensitivities(lin, outputs, velocities)
    for i, sig in enumerate(outputs):
        T, r = _row(lin, sig)
        # Columns: δz, the kinematic coordinates δy^k (nonholonomic models), δż.
        if sig.keyword in ("OUTX", "OUTE"):
            C[i, :n] = sens["x" if sig.keyword == "OUTX" else "e"][r]
            C[i, n:n + k] = sens["x_y" if sig.keyword == "OUTX" else "e_y"][r]
        elif sig.keyword in ("OUTXP", "OUTEP"):
            C[i, n + k:] = T[r]
            C[i, :n] = sens["xd" if sig.keyword == "OUTXP" else "ed"][r]
            C[i, n:n + k] = sens["xd_y" if sig.keyword == "OUTXP" else "ed_y"][r]
        else:
            C[i, :n], C[i, n:n + k], C[i, n + k:] = sens["sigma"][r], sens["sigma_y"][r], sens["sigma_d"][r]
    states = z_names + [f"e({a},{b})" for _, a, b in getattr(lin, "y_labels", [])] + \
        [name.replace("(", "d(", 1) for name in z_names]
    return StateSpace(A, B, C, np.zeros((len(outputs), len(inputs))), states,
                      [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in inputs],
                      [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in outputs], lin.t, lin,
                      None if k else (lin.M0, lin.damping, lin.stiffness, Q))


def _massless_directions(M):
    """(V, N): bases of the directions of z with mass and without (M N = 0), or None when M is
    regular. Decided on M scaled to a unit diagonal (D^-½ M D^-½; its zero rows are the DOFs
    without any mass), where translations and rotations, light and heavy parts compare: a model
    whose every DOF carries mass is not condensed however ill-conditioned its M is."""
    d = np.diag(M).copy()
    s = np.where(d > 0, 1.0 / np.sqrt(np.where(d > 0, d, 1.0)), 1.0)
    w, basis = np.linalg.eigh(s[:, None] * ((M + M.T) / 2) * s[None, :])
    heavy = w > 1e-13 * max(w.max(initial=0.0), 1e-300)
    if heavy.all():
        return None
    # Back to z, and orthonormal again (the spans are what matter; orthonormal keeps them accurate).
    return np.linalg.qr(s[:, None] * basis[:, heavy])[0], np.linalg.qr(s[:, None] * basis[:, ~heavy])[0]


def _build_condensed(lin, inputs, outputs, Q, sens, V, N) -> StateSpace:
    """The state space of a model with massless degrees of freedom (a flexure whose leaves carry
    no mass, its stage a point mass): the massless directions N follow the others statically,
    z = T a + S u with T = V − N (Nᵀ K N)⁻¹ Nᵀ K V, S = N (Nᵀ K N)⁻¹ Nᵀ Q (exact when no damping
    acts in them), and the states are a, ȧ in the directions V with mass, whose equations
    Vᵀ (M z̈ + C ż + K z − Q u) = 0 remain (K need not be symmetric)."""
    M, C, K = lin.M0, lin.damping, lin.stiffness
    size = max(np.abs(C).max(initial=0.0), 1e-300)
    if np.abs(N.T @ C).max(initial=0.0) > 1e-12 * size or np.abs(C @ N).max(initial=0.0) > 1e-12 * size:
        raise InputError("state_space: degrees of freedom without mass but with damping (EDAMPP, or the motion's "
                         "velocity terms) follow first-order dynamics that the state space does not model: give them "
                         "mass (e.g. the leaves' EMASS) or remove their damping")
    Knn = N.T @ K @ N
    try:
        follow = np.linalg.solve(Knn, np.hstack([N.T @ K @ V, N.T @ Q]))
    except np.linalg.LinAlgError:
        raise InputError("state_space: the degrees of freedom without mass have no stiffness of their own (a "
                         "mechanism without mass): give them mass") from None
    T = V - N @ follow[:, :V.shape[1]]
    S = N @ follow[:, V.shape[1]:]
    n, m = V.shape[1], len(inputs)
    Mr, Cr, Kr, Qr = V.T @ M @ T, V.T @ C @ T, V.T @ K @ T, V.T @ (Q - K @ S)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(Mr, Kr), -np.linalg.solve(Mr, Cr)]])
    B = np.vstack([np.zeros((n, m)), np.linalg.solve(Mr, Qr)])
    Cm = np.zeros((len(outputs), 2 * n))
    D = np.zeros((len(outputs), m))
    for i, sig in enumerate(outputs):
        T_out, r = _row(lin, sig)
        if sig.keyword in ("OUTX", "OUTE"):
            row = sens["x" if sig.keyword == "OUTX" else "e"][r]
            Cm[i, :n], D[i] = row @ T, row @ S
        elif sig.keyword in ("OUTXP", "OUTEP"):
            Cm[i, n:] = T_out[r] @ T
            Cm[i, :n] = sens["xd" if sig.keyword == "OUTXP" else "ed"][r] @ T
            if np.abs(T_out[r] @ S).max(initial=0.0) > 1e-12 * max(np.abs(Cm[i]).max(initial=0.0), 1e-300):
                raise InputError(f"{_where(sig)}: a rate that follows the inputs' rate through massless degrees of "
                                 "freedom is not a proper output (give them mass, or take the position)")
        else:
            Cm[i, :n], Cm[i, n:] = sens["sigma"][r] @ T, sens["sigma_d"][r] @ T
            D[i] = sens["sigma"][r] @ S
    states = [f"mass({i + 1})" for i in range(n)] + [f"massd({i + 1})" for i in range(n)]
    return StateSpace(A, B, Cm, D, states, [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in inputs],
                      [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in outputs], lin.t, lin, (Mr, Cr, Kr, Qr))


def _signal_index(sig: Signal, coords: dict, defs: dict) -> int:
    """The column of the signal's coordinate ({(node, i): column}) or deformation ({(element, i): row})."""
    on_node = sig.keyword in NODE_SIGNALS
    table = coords if on_node else defs
    key = (sig.number, sig.index)
    if key not in table:
        what = "node {} has no coordinate {}" if on_node else "element {} has no deformation {}"
        raise InputError(f"{_where(sig)}: {what.format(*key)}")
    return table[key]


_CONSTITUTIVE = (_core.DefClass.released, _core.DefClass.dynamic)


def _require_constitutive(sig: Signal, cls) -> None:
    """An OUTS output's deformation must carry a constitutive stress (its class DYNE or released)."""
    if cls not in _CONSTITUTIVE:
        raise InputError(f"{_where(sig)}: OUTS needs a DYNE or released deformation (its stress is "
                         "constitutive, σ = S e + D ė); this one is a reaction stress")


def _input_loads(inputs, index, moves, def_class, b_row, nx: int) -> np.ndarray:
    """The loads on the coordinates (nx x m) of force and stress inputs: a unit force on a
    coordinate that moves (``moves``: a mask over the coordinates), or −B_kᵀ of a constitutive
    deformation (``b_row(k)``: its row of B, dense)."""
    F = np.zeros((nx, len(inputs)))
    for j, sig in enumerate(inputs):
        i = index(sig)
        if sig.keyword == "INPUTF":
            if not moves[i]:
                raise InputError(f"{_where(sig)}: the input does no work on the degrees of freedom (a fixed or "
                                 "input coordinate, or one the constraints hold still)")
            F[i, j] = 1.0
        else:
            if def_class[i] not in _CONSTITUTIVE:
                raise InputError(f"{_where(sig)}: the input does no work on the degrees of freedom (a deformation "
                                 "that is not DYNE or released)")
            F[:, j] = -b_row(i)
    return F


def _build_modal(lin: Linearization, inputs, outputs, modes) -> StateSpace:
    """The state space in the lowest undamped modes from the nodal matrices (state_space's
    ``modes``)."""
    nodal = getattr(lin, "nodal", None)
    if nodal is None:
        raise InputError("state_space: modes= needs a state at rest in static equilibrium (e.g. after "
                         "spacar.static, or an unloaded model at rest), where the sparse nodal matrices apply; "
                         "this one is not (the dense model, without modes=, is)")
    if lin.n_line:
        raise InputError("state_space: modes= is for models without LINE parameters")
    lin._require_mass("state_space's modes")
    sim = lin._sim
    k = _count(modes, len(lin.z_labels))
    w2, vx = nodal.modes(sim, k)
    mass = np.einsum("ij,ij->j", vx, nodal.M @ vx)
    if not np.all(mass > 0):
        raise InputError("state_space: a mode moves no mass (a degree of freedom without inertia)")
    phi = vx / np.sqrt(mass)                                   # Φᵀ M Φ = I
    nx = nodal.M.shape[0]
    free = np.zeros(nx, dtype=bool)
    free[nodal.free] = True
    defs = {label: i for i, label in enumerate(lin.deformation_labels)}
    coords = {label: i for i, label in enumerate(lin.coordinate_labels)}
    classes = sim.system.def_class

    def index(sig):
        return _signal_index(sig, coords, defs)

    # Loads on the coordinates of the inputs (nx x m): a force, or −B_kᵀ for a stress.
    F = _input_loads(inputs, index, free, classes, lambda k: nodal.B[k].toarray().ravel(), nx)
    # Outputs over the coordinates: positions (and the stresses' elastic part) and rates.
    Cx, Cv = np.zeros((len(outputs), nx)), np.zeros((len(outputs), nx))
    for r, sig in enumerate(outputs):
        i = index(sig)
        if sig.keyword == "OUTX":
            Cx[r, i] = 1.0
        elif sig.keyword == "OUTXP":
            Cv[r, i] = 1.0
        elif sig.keyword == "OUTE":
            Cx[r] = nodal.B[i].toarray().ravel()
        elif sig.keyword == "OUTEP":
            Cv[r] = nodal.B[i].toarray().ravel()
        else:
            _require_constitutive(sig, classes[i])
            Cx[r] = (nodal.S[i] @ nodal.B).toarray().ravel()
            Cv[r] = (nodal.Dc[i] @ nodal.B).toarray().ravel()
    Q = phi.T @ F
    damping = phi.T @ (nodal.D @ phi)
    A = np.block([[np.zeros((k, k)), np.eye(k)], [-np.diag(w2), -damping]])
    B = np.vstack([np.zeros((k, len(inputs))), Q])
    C = np.hstack([Cx @ phi, Cv @ phi])
    # The static response of the modes left out, as a feedthrough: C (K⁻¹ − Φ Ω⁻² Φᵀ) F.
    D = np.zeros((len(outputs), len(inputs)))
    if len(inputs) and np.any(Cx):
        info = sim.nodal_factorize(1.0, 1.0, 0.0, 0.0)
        if not info["ok"] or info["singular"]:
            raise InputError("state_space: the stiffness K0 + G0 is singular (a free rigid-body motion): the "
                             "static correction of the truncated modes needs a supported model")
        static = np.zeros((nx, len(inputs)))
        for j in range(len(inputs)):
            static[nodal.free, j] = sim.nodal_solve(F[nodal.free, j])
        D = Cx @ (static - phi @ (Q / w2[:, None]))
    states = [f"mode({i + 1})" for i in range(k)] + [f"moded({i + 1})" for i in range(k)]
    return StateSpace(A, B, C, D, states, [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in inputs],
                      [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in outputs], lin.t, lin,
                      (np.eye(k), damping, np.diag(w2), Q))


def _build_base(lin, sim, inputs, outputs, ratios, alpha, beta) -> StateSpace:
    """The state space at rest with the supports' motion as inputs (BASEX/BASEXP/BASEXPP: the
    position, velocity or acceleration of INPUTX coordinates) and accelerations (OUTXPP) and
    reactions (OUTR) among the outputs, from the nodal matrices (docs/linearization.md,
    "Base motion").

    The coordinates move as x = Z z + U u (Z = DF of the DOFs, U of the inputs u: the motion of
    every coordinate per unit input at fixed DOFs), so that

        M z̈ + C ż + K z = −M_u ü − C_u u̇ − K_u u + Q f,    M_u = Zᵀ M_n U, ...

    with M_n, C_n, H_n = K_n + G_n the nodal mass, damping and tangent stiffness. An input
    prescribing the acceleration a of u keeps u and u̇ as states; the velocity v, u as a state;
    the position, neither: the DOFs are then shifted, z̃ = z + M⁻¹ M_0 u_0 and
    p = ż̃ + M⁻¹ (M_1 v_1 − E_0 u_0), E_0 = C M⁻¹ M_0 − C_0, which removes the inputs' derivatives
    from the equations (a proper realization). An output that follows a derivative of its input
    the realization has not (the rate of a node under a position input coupled by mass) is refused."""
    nodal = getattr(lin, "nodal", None)
    if nodal is None or lin.n_line or getattr(lin, "y_labels", []):
        raise InputError("state_space: the supports' motion (BASEX, BASEXP, BASEXPP), accelerations (OUTXPP) and "
                         "reactions (OUTR) need a state at rest in static equilibrium without LINE parameters or "
                         "nonholonomic constraints (e.g. after spacar.static, or an unloaded model at rest)")
    lin._require_mass("the state space with the supports' motion")
    from .transfer import _q_labels

    # DF with the columns of the inputs too (the kinematic analysis at the state, no D2F).
    system = sim.system
    q_labels, is_input = _q_labels(system)
    sim.kinematic_state(lin.t, np.asarray(system.q0, dtype=float))
    DF_all = np.array(sim.data.DF).reshape(-1, len(q_labels))
    Z = np.asarray(lin.DF, dtype=float)
    n, nx = Z.shape[1], Z.shape[0]
    coords = {label: i for i, label in enumerate(lin.coordinate_labels)}
    defs = {label: i for i, label in enumerate(lin.deformation_labels)}
    coord_class, def_class = list(system.coord_class), list(system.def_class)
    Mn, Cn, Hn = nodal.M, nodal.D, nodal.K + nodal.G
    B = nodal.B.toarray()

    def index(sig):
        return _signal_index(sig, coords, defs)

    # The inputs: loads F on the coordinates (forces, stresses), the supports' motion U.
    base = [s for s in inputs if s.keyword in _BASE_ORDER]
    forces = [s for s in inputs if s.keyword not in _BASE_ORDER]
    F = _input_loads(forces, index, np.any(Z != 0, axis=1), def_class, lambda k: B[k], nx)
    U = np.zeros((nx, len(base)))
    for j, sig in enumerate(base):
        label = ("x", sig.number, sig.index)
        if label not in q_labels or not is_input[q_labels.index(label)]:
            raise InputError(f"{_where(sig)}: coordinate {sig.index} of node {sig.number} is not an INPUTX coordinate "
                             "(a support's motion is prescribed on an input coordinate)")
        U[:, j] = DF_all[:, q_labels.index(label)]
    M, C, K = (np.asarray(Z.T @ (A @ Z)) for A in (Mn, Cn, Hn))
    Mu, Cu, Ku = (np.asarray(Z.T @ (A @ U)) for A in (Mn, Cn, Hn))
    Q = Z.T @ F
    # Added damping (damping=, rayleigh=) acts on the motion relative to the quasi-static one
    # that follows the supports (z = −K⁻¹ K_u u): a support's rigid motion is not damped.
    extra = _added_damping(M, K, ratios, alpha, beta)
    reactions = [sig for sig in outputs if sig.keyword == "OUTR"]
    if reactions and (alpha or ratios is not None):
        raise InputError(f"{_where(reactions[0])}: a reaction with modal or mass-proportional added damping is not "
                         "defined (those forces act on the degrees of freedom, not through the elements): model the "
                         "damping as EDAMPP or rayleigh=(0, β)")
    if np.any(extra):
        try:
            Cu = Cu + extra @ np.linalg.solve(K, Ku)
        except np.linalg.LinAlgError:
            raise InputError("state_space: damping= and rayleigh= with the supports' motion need a supported model "
                             "(K0 + G0 regular)") from None
        C = C + extra
    # The outputs as rows over x, ẋ, ẍ of the coordinates, and over the force inputs.
    rows = {"x": np.zeros((len(outputs), nx)), "v": np.zeros((len(outputs), nx)), "a": np.zeros((len(outputs), nx))}
    cf = np.zeros((len(outputs), len(forces)))
    for r, sig in enumerate(outputs):
        i = index(sig)
        if sig.keyword in ("OUTX", "OUTXP", "OUTXPP"):
            rows[{"OUTX": "x", "OUTXP": "v", "OUTXPP": "a"}[sig.keyword]][r, i] = 1.0
        elif sig.keyword in ("OUTE", "OUTEP"):
            rows["x" if sig.keyword == "OUTE" else "v"][r] = B[i]
        elif sig.keyword == "OUTS":
            _require_constitutive(sig, def_class[i])
            rows["x"][r] = nodal.S[i] @ B
            rows["v"][r] = nodal.Dc[i] @ B
        else:  # OUTR
            rho = _reaction_row(sig, i, coord_class, def_class, B)
            # Stiffness-proportional added damping, β H_n on the nodal rates, is carried by the elements.
            rows["x"][r], rows["v"][r], rows["a"][r] = Hn.T @ rho, (Cn + beta * Hn).T @ rho, Mn.T @ rho
            cf[r] = -rho @ F
    return _realize(M, C, K, Mu, Cu, Ku, Q, Z, U, rows, cf, inputs, outputs, base, forces, lin)


def _reaction_row(sig, g, coord_class, def_class, B) -> np.ndarray:
    """ρ with the reaction at coordinate g = ρᵀ (M_n ẍ + C_n ẋ + H_n x − F f): the coordinate's own
    row, and the reaction stresses of the rigid and input deformations (rows R) that hold the
    calculable coordinates c in equilibrium, B_R[:, c]ᵀ λ = F f − w_c."""
    if coord_class[g] not in (_core.CoordClass.fixed, _core.CoordClass.input):
        raise InputError(f"{_where(sig)}: a reaction acts on a fixed or INPUTX coordinate; coordinate {sig.index} of "
                         f"node {sig.number} moves freely")
    rho = np.zeros(B.shape[1])
    rho[g] = 1.0
    held = [k for k, c in enumerate(def_class) if c in (_core.DefClass.fixed, _core.DefClass.input)]
    calc = [c for c, k in enumerate(coord_class) if k == _core.CoordClass.calculable]
    if held and calc and np.any(B[held, g]):
        rho[calc] = -np.linalg.lstsq(B[np.ix_(held, calc)], B[held, g], rcond=None)[0]
    return rho


def _realize(M, C, K, Mu, Cu, Ku, Q, Z, U, rows, cf, inputs, outputs, base, forces, lin) -> StateSpace:
    """A, B, C, D of the equations with the supports' motion (see _build_base)."""
    n = M.shape[0]
    if _massless_directions(M) is not None:
        raise SingularMassError("state_space: the supports' motion and the accelerations and reactions need every "
                                "degree of freedom to carry mass (the reduced mass matrix is singular): give the "
                                "massless parts their EMASS")
    order = np.array([_BASE_ORDER[s.keyword] for s in base], dtype=int)
    o0, o1, o2 = (np.nonzero(order == k)[0] for k in (0, 1, 2))
    Mi = np.linalg.inv(M)
    E0 = C @ Mi @ Mu[:, o0] - Cu[:, o0]
    F0 = K @ Mi @ Mu[:, o0] - Ku[:, o0]
    # States [z̃, p, u of velocity and acceleration inputs, u̇ of acceleration inputs].
    nu1, nu2 = len(o1), len(o2)
    ns = 2 * n + nu1 + 2 * nu2
    iz, ip = slice(0, n), slice(n, 2 * n)
    iu1 = slice(2 * n, 2 * n + nu1)
    iu2 = slice(2 * n + nu1, 2 * n + nu1 + nu2)
    iv2 = slice(2 * n + nu1 + nu2, ns)
    # The inputs' columns in the user's order.
    col = {("f", j): inputs.index(s) for j, s in enumerate(forces)}
    col.update({("u", j): inputs.index(s) for j, s in enumerate(base)})
    m = len(inputs)
    A = np.zeros((ns, ns))
    Bm = np.zeros((ns, m))
    A[iz, ip] = np.eye(n)
    A[ip, ip] = -Mi @ C
    A[ip, iz] = -Mi @ K
    A[ip, iu1] = -Mi @ Ku[:, o1]
    A[ip, iu2] = -Mi @ Ku[:, o2]
    A[ip, iv2] = -Mi @ Cu[:, o2]
    A[iu2, iv2] = np.eye(nu2)
    for j in range(len(forces)):
        Bm[ip, col[("f", j)]] = Mi @ Q[:, j]
    for a, j in enumerate(o0):
        Bm[iz, col[("u", j)]] = Mi @ E0[:, a]
        Bm[ip, col[("u", j)]] = Mi @ (-C @ Mi @ E0[:, a] + F0[:, a])
    for a, j in enumerate(o1):
        Bm[iz, col[("u", j)]] = -Mi @ Mu[:, j]
        Bm[ip, col[("u", j)]] = Mi @ (C @ Mi @ Mu[:, j] - Cu[:, j])
        Bm[iu1.start + a, col[("u", j)]] = 1.0
    for a, j in enumerate(o2):
        Bm[ip, col[("u", j)]] = -Mi @ Mu[:, j]
        Bm[iv2.start + a, col[("u", j)]] = 1.0
    # The outputs: y = cz z + czd ż + czdd z̈ + cu u + cud u̇ + cudd ü + cf f, z̈ from the equations.
    cz, czd, czdd = rows["x"] @ Z, rows["v"] @ Z, rows["a"] @ Z
    cu, cud, cudd = rows["x"] @ U, rows["v"] @ U, rows["a"] @ U
    G = czdd @ Mi
    # The size of the terms that make up the coefficients of u̇ and ü, against which a remainder
    # counts as a real dependence (rather than their rounding) for the properness check below.
    # (The bounds of the products' rounding: each factor taken by its size, M⁻¹ by that of its
    # Jacobi-scaled inverse, so that a light mass beside heavy ones does not inflate the bound.)
    dm = np.sqrt(np.abs(np.diag(M)))
    absMi = np.abs(np.linalg.inv(M / np.outer(dm, dm))) / np.outer(dm, dm)
    absG = np.abs(czdd) @ absMi
    abs_czd = np.abs(czd) + absG @ np.abs(C)
    size_ud = np.abs(rows["v"]) @ np.abs(U) + absG @ np.abs(Cu)
    size_udd = np.abs(rows["a"]) @ np.abs(U) + absG @ np.abs(Mu)
    cz, czd = cz - G @ K, czd - G @ C
    cu, cud, cudd = cu - G @ Ku, cud - G @ Cu, cudd - G @ Mu
    cf = cf + G @ Q
    Cm = np.zeros((len(outputs), ns))
    Dm = np.zeros((len(outputs), m))
    # z = z̃ − M⁻¹ M_0 u_0;  ż = p − M⁻¹ M_1 v_1 + M⁻¹ E_0 u_0 − M⁻¹ M_0 u̇_0.
    Cm[:, iz], Cm[:, ip] = cz, czd
    for a, j in enumerate(o0):
        Dm[:, col[("u", j)]] += -cz @ Mi @ Mu[:, j] + czd @ Mi @ E0[:, a]
        cud[:, j] = cud[:, j] - czd @ Mi @ Mu[:, j]
        size_ud[:, j] += abs_czd @ (absMi @ np.abs(Mu[:, j]))
    for j in o1:
        Dm[:, col[("u", j)]] += -czd @ Mi @ Mu[:, j]
    for j in range(len(forces)):
        Dm[:, col[("f", j)]] += cf[:, j]
    for a, j in enumerate(o1):
        Cm[:, iu1.start + a] += cu[:, j]
        Dm[:, col[("u", j)]] += cud[:, j]
    for a, j in enumerate(o2):
        Cm[:, iu2.start + a] += cu[:, j]
        Cm[:, iv2.start + a] += cud[:, j]
        Dm[:, col[("u", j)]] += cudd[:, j]
    for j in o0:
        Dm[:, col[("u", j)]] += cu[:, j]
    # A derivative of an input the realization does not have: improper.
    for what, coefficient, size, orders in (("rate", cud, size_ud, (0,)), ("acceleration", cudd, size_udd, (0, 1))):
        for j in np.nonzero(np.isin(order, orders))[0]:
            bad = np.nonzero(np.abs(coefficient[:, j]) > 1e-8 * size[:, j])[0]
            if bad.size:
                raise InputError(f"{_where(outputs[bad[0]])}: this output follows the {what} of input "
                                 f"{_where(base[j])} (its response is not proper): take the velocity or acceleration "
                                 "of the support as the input (BASEXP, BASEXPP)")
    z_names = [f"{kind}({a},{b})" for kind, a, b in lin.z_labels]
    states = z_names + [f"p({name})" for name in z_names] + \
        [f"u({s.number},{s.index})" for s in (base[j] for j in o1)] + \
        [f"u({s.number},{s.index})" for s in (base[j] for j in o2)] + \
        [f"ud({s.number},{s.index})" for s in (base[j] for j in o2)]
    _check_static_gain(A, Bm, Cm, Dm, K, Ku, Z, U, rows["x"], o0, col, base, outputs)
    return StateSpace(A, Bm, Cm, Dm, states, [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in inputs],
                      [f"{_NAMES[s.keyword]}({s.number},{s.index})" for s in outputs], lin.t, lin)


def _check_static_gain(A, B, C, D, K, Ku, Z, U, rows_x, o0, col, base, outputs):
    """The shifted coordinates of a position input cancel large terms (stiff, damped elements):
    the realization's static response to each position input must be the structure's own,
    rows_x (Z z + U u) with K z = −K_u u, or the model is refused rather than returned wrong."""
    if not len(o0) or np.linalg.cond(A) > 1e14 or np.linalg.cond(K) > 1e14:
        return
    for j in o0:
        exact = rows_x @ (Z @ np.linalg.solve(K, -Ku[:, j]) + U[:, j])
        realized = C @ np.linalg.solve(A, -B[:, col[("u", j)]]) + D[:, col[("u", j)]]
        scale = max(np.abs(exact).max(initial=0.0), 1e-300)
        if np.abs(realized - exact).max(initial=0.0) > 1e-6 * scale:
            raise InputError(f"{_where(base[j])}: the realization of this position input loses its accuracy (its static "
                             f"response is off by {np.abs(realized - exact).max() / scale:.2g}: large stiffness and "
                             "damping terms cancel in the shifted coordinates); take the velocity or acceleration "
                             "of the support as the input (BASEXP, BASEXPP), the same transfer over s or s²")


def _sensitivities(lin, outputs, velocities) -> dict:
    """What the outputs need beyond DF and DFe, at fixed ż: "xd", "ed" (∂ẋ/∂z, ∂ė/∂z, the
    convective terms of the rates: zero at rest), "sigma", "sigma_d" (∂σ/∂z, ∂σ/∂ż of the
    stresses), "x", "e" (∂x/∂z, ∂e/∂z of the positions: DF and DFe, except with nonholonomic
    constraints, whose DF and DFe are the velocity transfer ẋ = DF ż, not the positions'
    derivatives at fixed y^k) and, with nonholonomic constraints, the derivatives over their
    kinematic coordinates y^k at fixed z and ż: "x_y", "e_y", "xd_y", "ed_y", "sigma_y". Those
    not zero come from central differences, with the kinematics re-solved (sim.move_to, or
    sim.evaluate_state with y^k) and the stresses evaluated."""
    nx, ne, n = lin.DF.shape[0], lin.DFe.shape[0], lin.M0.shape[0]
    k = len(getattr(lin, "y_labels", []))
    rows = {"x": nx, "xd": nx, "e": ne, "ed": ne, "sigma": ne}  # of each quantity
    out = {name: np.zeros((rows[name], n)) for name in ("xd", "ed", "sigma")}
    out["sigma_d"] = np.zeros((ne, n))
    out["x"], out["e"] = np.array(lin.DF), np.array(lin.DFe)
    out.update({f"{name}_y": np.zeros((size, k)) for name, size in rows.items()})
    stresses = [s for s in outputs if s.keyword == "OUTS"]
    rates = [s for s in outputs if s.keyword in ("OUTXP", "OUTEP")]
    positions = [s for s in outputs if s.keyword in ("OUTX", "OUTE")]
    # At rest (no coordinate moving: ż = 0 and the input motions still) the convective terms
    # vanish; a Linearization alone does not say.
    at_rest = velocities is not None and not np.any(np.asarray(velocities[0].data.xd))
    nodal = lin.__dict__.get("nodal")
    if velocities is not None:
        classes = velocities[0].system.def_class
        for sig in stresses:
            _require_constitutive(sig, classes[lin.deformation_labels.index((sig.number, sig.index))])
    if stresses and at_rest and nodal is not None:
        # δσ = S δe + Dc δė with δe = B DF δz: exact, from the nodal matrices (no differences,
        # no equations of motion: a model with massless DOFs too).
        BDF = nodal.B @ lin.DF
        out["sigma"], out["sigma_d"] = np.asarray(nodal.S @ BDF), np.asarray(nodal.Dc @ BDF)
        stresses = []
    needed = stresses + ([] if at_rest else rates) + (positions if k else [])
    if not needed:
        return out
    first = needed[0]
    if velocities is None or lin.n_line:
        position = "a position output of a nonholonomic model"
        what = {"OUTS": "a stress output", "OUTX": position, "OUTE": position}.get(
            first.keyword, "a rate output at a moving state")
        why = ("a Linearization alone cannot be re-evaluated: pass the Model" if velocities is None else
               "they are computed for models without LINE parameters only")
        raise InputError(f"{_where(first)}: {what} needs differences of the kinematics or stresses; {why}")
    sim, (t, q, qd) = velocities
    y_defs = list(sim.system.y_defs)
    y = np.array([sim.data.e_integrated[d] for d in y_defs])
    # The kinematic coordinates' places in y (the integrated deformations, slips among them).
    ky = [y_defs.index(lin.deformation_labels.index((a, b))) for _, a, b in getattr(lin, "y_labels", [])]

    def at(qj, qdj, yj=y):
        if y_defs:  # the integrated deformations held at yj
            sim.evaluate_state(t, np.concatenate([qj, yj, qdj]))
        else:
            sim.move_to(t, qj, qdj)
        if stresses:
            sim.forces()
        d = sim.data
        return {"x": np.array(d.x), "e": np.array(d.e), "xd": np.array(d.xd), "ed": np.array(d.ed),
                "sigma": np.array(d.sigma)}

    def central(plus, minus, h, names):
        return ((plus[a] - minus[a]) / (2 * h) for a in names)

    eps = np.finfo(float).eps ** (1 / 3)
    for j in range(n):
        h = eps * max(abs(q[j]), 1.0)
        dq = np.zeros(n)
        dq[j] = h
        plus, minus = at(q + dq, qd), at(q - dq, qd)
        out["xd"][:, j], out["ed"][:, j], out["sigma"][:, j] = central(plus, minus, h, ("xd", "ed", "sigma"))
        if k:
            out["x"][:, j], out["e"][:, j] = central(plus, minus, h, ("x", "e"))
        if stresses:
            h = eps * max(abs(qd[j]), 1.0)
            dq[j] = h
            out["sigma_d"][:, j] = next(central(at(q, qd + dq), at(q, qd - dq), h, ("sigma",)))
    for i, p in enumerate(ky):
        h = eps * max(abs(y[p]), 1.0)
        dy = np.zeros(len(y))
        dy[p] = h
        out["x_y"][:, i], out["e_y"][:, i], out["xd_y"][:, i], out["ed_y"][:, i], out["sigma_y"][:, i] = central(
            at(q, qd, y + dy), at(q, qd, y - dy), h, ("x", "e", "xd", "ed", "sigma"))
    at(q, qd)  # back to the state itself
    if at_rest:
        out["xd"][:], out["ed"][:], out["xd_y"][:], out["ed_y"][:] = 0.0, 0.0, 0.0, 0.0
    return out


def _frequencies(freqs, unit) -> np.ndarray:
    if unit not in ("Hz", "rad/s"):
        raise InputError(f"unit must be 'Hz' or 'rad/s', got {show(unit)}")
    try:
        f = np.asarray(freqs, dtype=float).reshape(-1)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"freqs must be numbers, got {show(freqs)}") from None
    if not np.isfinite(f).all():
        raise InputError("freqs must be finite numbers")
    with np.errstate(over="ignore"):
        w = 2 * np.pi * f if unit == "Hz" else f
    if not np.isfinite(w).all():
        raise InputError(f"freqs: {float(f[~np.isfinite(w)][0]):g} Hz is beyond the angular frequencies double "
                         "precision holds")
    return w
