"""Linearized equations of motion, eigenfrequencies, mode shapes and buckling factors
(formulation.md §7).

About a state of the model (static or moving), in the coordinates z = (q, e^ℓ) — the degrees of
freedom followed by the LINE parameters:

    M0 δz̈ + (C0 + D0) δż + (K0 + N0 + G0) δz + K_k δy^k = r0
    δẏ^k = AK0 δż + BK0 [δz; δy^k]            (nonholonomic systems: y^k kinematic coordinates)

M0 reduced mass, C0 velocity sensitivity (Coriolis, centrifugal, gyroscopic), D0 structural
damping (EDAMPP), K0 structural stiffness (ESTIFF), N0 dynamic stiffness (inertia and
convective terms), G0 geometric stiffness (stresses incl. reaction stresses, load stiffness).
"""
from __future__ import annotations

import contextlib

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError, SingularMassError, SpacarError
from .model import Model


# The arrays of a linearization, by the names of its attributes (formulation.md §7): the core's
# one list (Linearization::for_each_array), which the constructors below and Results.save/load
# go by.
MATRICES = tuple(_core.linearization_arrays)


class Linearization:
    """The matrices of the linearized equations at one state, as NumPy arrays, with the
    eigen-analyses built on them.

    ``z_labels``: ("x", node, component) or ("e", element, deformation) of each z; ``y_labels``:
    ("e", element, deformation) of each kinematic coordinate y^k; the arrays named in
    :data:`MATRICES`; ``DF`` (∂x/∂z) and ``DFe`` (∂e/∂z) give the nodal coordinates and
    deformations per unit z (mode shapes)."""

    # Models with more degrees of freedom than this solve eigenfrequencies(k=...) and
    # buckling_factors(k=...) on the sparse nodal matrices (when they are available) rather than
    # the dense reduced ones (benchmarks/modes.py: the sparse path is the faster from about 50
    # degrees of freedom on).
    SPARSE_ABOVE = 50

    def __init__(self, d: dict, coordinate_labels, deformation_labels):
        """From the dictionary of the core (``Simulation.linearize()``, the on_output state)."""
        self._fill(d["t"], [("x" if k == 0 else "e", a, b) for k, a, b in d["z_label"]], d["n_line"],
                   [("e", a, b) for _, a, b in d["y_label"]],
                   {name: d[name] for name in MATRICES},
                   coordinate_labels, deformation_labels)

    @classmethod
    def from_arrays(cls, t, z_labels, n_line, matrices: dict, coordinate_labels, deformation_labels,
                    y_labels=None):
        """Rebuild from saved arrays (``matrices`` by the names of :data:`MATRICES`); used by
        :meth:`spacar.Results.load`. A file written before the kinematic coordinates were saved
        has neither ``y_labels`` nor Kk, AK0, BK0: those attributes stay absent."""
        self = cls.__new__(cls)
        self._fill(t, z_labels, n_line, y_labels, matrices, coordinate_labels, deformation_labels)
        return self

    def _fill(self, t, z_labels, n_line, y_labels, matrices, coordinate_labels, deformation_labels):
        self.t = float(t)
        self.z_labels = [(str(k), int(a), int(b)) for k, a, b in z_labels]
        self.n_line = int(n_line)
        for name in MATRICES:
            if name in matrices:
                setattr(self, name, np.asarray(matrices[name]))
        if y_labels is not None:
            self.y_labels = [(str(k), int(a), int(b)) for k, a, b in y_labels]
            # An empty matrix may come without its shape (nz x 0, 0 x nz).
            nz, nk = len(self.z_labels), len(self.y_labels)
            self.Kk = self.Kk.reshape(nz, nk)
            self.AK0 = self.AK0.reshape(nk, nz)
            self.BK0 = self.BK0.reshape(nk, nz + nk)
        self.coordinate_labels = [tuple(int(v) for v in c) for c in coordinate_labels]
        self.deformation_labels = [tuple(int(v) for v in c) for c in deformation_labels]

    @classmethod
    def _from_nodal(cls, d: dict, sim, state, coordinate_labels, deformation_labels):
        """A linearization at rest in static equilibrium from ``Simulation.linearize_nodal()``:
        the sparse nodal matrices now, the dense reduced ones (M0, ..., DF) on first use, from
        the simulation kept for it."""
        self = cls.__new__(cls)
        self.t = float(d["t"])
        self.z_labels = [("x" if k == 0 else "e", int(a), int(b)) for k, a, b in d["z_label"]]
        self.n_line = int(d["n_line"])
        self.y_labels = []
        self.r0 = np.asarray(d["r0"])
        self.coordinate_labels = [tuple(int(v) for v in c) for c in coordinate_labels]
        self.deformation_labels = [tuple(int(v) for v in c) for c in deformation_labels]
        self.nodal = NodalMatrices(d, self.coordinate_labels)
        self._sim, self._state = sim, state
        return self

    def __getattr__(self, name):
        # The dense reduced matrices of a nodal linearization, computed when first asked for.
        if name in MATRICES and "_sim" in self.__dict__ and not self.__dict__.get("_dense", False):
            self._densify()
            return getattr(self, name)
        raise AttributeError(f"{type(self).__name__!s} has no attribute {name!r}")

    def _densify(self):
        """The dense reduced matrices (formulation.md §7) at the nodal linearization's state."""
        sim = self._sim
        t, q, _ = self._state
        # At rest in static equilibrium: C0 = N0 = 0, q̈ = 0 and the static stresses, no equations
        # of motion (a model without mass has its K0, G0 and DF; M0 = 0).
        d = sim.linearize_at_rest(t, q)
        nz = len(self.z_labels)
        for name in MATRICES:
            if name != "r0":
                setattr(self, name, np.asarray(d[name]))
        self.Kk = self.Kk.reshape(nz, 0)
        self.AK0 = self.AK0.reshape(0, nz)
        self.BK0 = self.BK0.reshape(0, nz)
        self._dense = True

    def __getstate__(self):
        # A pickle holds the arrays, not the simulation: the dense matrices are computed first.
        if "_sim" in self.__dict__ and not self.__dict__.get("_dense", False):
            self._densify()
        return {k: v for k, v in self.__dict__.items() if k not in ("_sim", "_state")}

    def _sparse(self, k, method) -> bool:
        """Whether an eigen-analysis of k values takes the sparse nodal path."""
        if method not in ("auto", "dense", "sparse"):
            raise InputError(f"method must be 'auto', 'dense' or 'sparse', got {show(method)}")
        nodal, nz = "_sim" in self.__dict__, len(self.z_labels)
        if method == "sparse":
            if not nodal:
                raise InputError("the sparse eigen-analysis needs a linearization at rest in static equilibrium "
                                 "from spacar.linearize(model) (this one is not)")
            if k is None or not k < nz - 1:
                raise InputError(f"the sparse eigen-analysis computes the lowest k values, k < {nz - 1} (the "
                                 f"coordinates less one; use method='dense' for all): got k = {show(k)}")
            return True
        return method == "auto" and nodal and k is not None and nz > self.SPARSE_ABOVE and k < nz - 1

    @property
    def stiffness(self) -> np.ndarray:
        """K0 + N0 + G0."""
        return self.K0 + self.N0 + self.G0

    @property
    def damping(self) -> np.ndarray:
        """C0 + D0."""
        return self.C0 + self.D0

    def _undamped(self):
        """(ω², vectors) of all undamped modes, sorted by |ω²|: in the modal basis of a symmetric
        pencil (the inverse pencil when the stiffness is positive definite: the lowest modes to
        full relative precision, see _modal_basis), SciPy's QZ otherwise."""
        M, K = self.M0, self.stiffness
        _core.check_deadline("(in the eigen-analysis)")  # a sweep's time_limit, between the dense steps
        basis = _modal_basis(M, K)
        if basis is None:
            import scipy.linalg  # lazily: `import spacar` stays light

            w2, v = scipy.linalg.eig(self.stiffness, self.M0)
            w2 = np.real_if_close(w2, tol=1e6)
        else:
            w2, v = basis
        order = np.argsort(np.abs(w2))
        return np.real(w2[order]), v[:, order]

    def _require_mass(self, what: str):
        """A SingularMassError for an analysis that needs masses when no node or element carries
        any (a flexure model built for its stiffness: its K0, G0, buckling factors, compliance
        and support stiffness need none)."""
        if not self.z_labels:
            return  # nothing moves: every result is empty
        nodal = self.__dict__.get("nodal")
        massless = nodal.M.count_nonzero() == 0 if nodal is not None else not np.any(self.M0)
        if massless:
            raise SingularMassError(f"{what} needs masses: no node or element of the model carries mass (add MASS "
                                    "or EMASS, e.g. spacar.section's emass); its stiffness K0, G0, the buckling "
                                    "factors, the compliance and the support stiffness need none")

    def _modes(self, k, method):
        """(ω², shapes in z, shapes in x) of the k lowest |ω²| (all if k is None)."""
        self._require_mass("the eigen-analysis")
        if self._sparse(k, method):
            w2, vx = self.nodal.modes(self._sim, _count(k, len(self.z_labels)))
            return w2, self.nodal.E @ vx, vx
        w2, v = self._undamped()
        if k is not None:
            k = _count(k, len(self.z_labels))
            w2, v = w2[:k], v[:, :k]
        v = np.real(v)
        return w2, v, None

    def eigenfrequencies(self, k=None, *, method: str = "auto") -> np.ndarray:
        """Undamped eigenfrequencies in Hz, sorted, from (K0 + N0 + G0) v = ω² M0 v. An unstable
        mode (ω² < 0) is returned as a negative number −√|ω²|/2π.

        ``k``: only the k lowest (by |ω²|; None: all). ``method``: "dense" solves the reduced
        matrices (all modes, small models); "sparse" the nodal matrices of a linearization at
        rest in static equilibrium (docs/formulation.md §10) for the k lowest, in shift-invert mode
        (ARPACK), with a cost that grows linearly with the mesh; "auto" (default) takes the
        sparse path when k is given (fewer than the coordinates less one), the linearization has
        it, and the model has more than ``Linearization.SPARSE_ABOVE`` (50) degrees of freedom."""
        w2 = self._modes(k, method)[0]
        return np.sign(w2) * np.sqrt(np.abs(w2)) / (2 * np.pi)

    def mode_shapes(self, k=None, *, method: str = "auto"):
        """(frequencies in Hz, shapes in z (nz x nmodes), shapes in the nodal coordinates
        (nx x nmodes)). Each shape in z is normalised to unit largest component (sign
        arbitrary); the nodal shapes are DF times the same vectors, so both describe the same
        motion (their largest component is generally not 1). ``k``, ``method``: as
        :meth:`eigenfrequencies`."""
        w2, v, vx = self._modes(k, method)
        if v.size:
            scale = np.abs(v).max(axis=0)
            v = v / scale
            vx = self.DF @ v if vx is None else vx / scale
        elif vx is None:
            vx = self.DF @ v
        return np.sign(w2) * np.sqrt(np.abs(w2)) / (2 * np.pi), v, vx

    def state_matrix(self) -> np.ndarray:
        """A of d/dt [δz; δy^k; δż] = A [δz; δy^k; δż] (formulation.md §7.3); without
        nonholonomic constraints just d/dt [δz; δż]."""
        self._require_mass("the state matrix")
        n, k = self.M0.shape[0], len(self.y_labels)
        Minv = np.linalg.inv(self.M0)
        return np.block([
            [np.zeros((n, n)), np.zeros((n, k)), np.eye(n)],
            [self.BK0[:, :n], self.BK0[:, n:], self.AK0],
            [-Minv @ self.stiffness, -Minv @ self.Kk, -Minv @ self.damping],
        ])

    def eigenvalues(self) -> np.ndarray:
        """Eigenvalues of the first-order system (damping, gyroscopic terms included), sorted by
        |Im| and then Re."""
        self._require_mass("the eigen-analysis")
        lam = None if len(self.y_labels) else second_order_eigenvalues(self.M0, self.damping, self.stiffness)
        if lam is None:
            lam = np.linalg.eigvals(self.state_matrix())
        return lam[np.lexsort((lam.real, np.abs(lam.imag)))]

    def buckling_factors(self, k=None, *, method: str = "auto") -> np.ndarray:
        """Load multipliers μ of (K0 + μ G0) v = 0 for a static state, sorted by |μ|; only the
        finite ones. ``k``, ``method``: as :meth:`eigenfrequencies` (the sparse path gives the k
        smallest |μ| and needs no mass)."""
        if self._sparse(k, method):
            return self.nodal.buckling(self._sim, _count(k, len(self.z_labels)))[0]
        import scipy.linalg

        mu = scipy.linalg.eigvals(-self.K0, self.G0)
        mu = mu[np.isfinite(mu)]
        mu = np.real_if_close(mu, tol=1e6)
        mu = np.real(mu[np.argsort(np.abs(mu))]) if np.isrealobj(mu) else mu[np.argsort(np.abs(mu))]
        return mu if k is None else mu[:_count(k, len(self.z_labels))]

    def buckling_modes(self, k=None, *, method: str = "auto"):
        """(μ, shapes in z (nz x n), shapes in the nodal coordinates (nx x n)) of
        (K0 + μ G0) v = 0: the real, finite buckling factors sorted by |μ| (as
        :meth:`buckling_factors`, complex ones left out) with their mode shapes, each normalised
        to unit largest component in z (sign arbitrary); the nodal shapes are DF v, drawable with
        ``spacar.draw(res, mode=shapes_x[:, i])``. ``k``, ``method``: as :meth:`eigenfrequencies`."""
        if self._sparse(k, method):
            mu, vx = self.nodal.buckling(self._sim, _count(k, len(self.z_labels)))
            v = self.nodal.E @ vx
            scale = np.abs(v).max(axis=0) if v.size else 1.0
            return mu, v / scale, vx / scale
        import scipy.linalg

        mu, v = scipy.linalg.eig(-self.K0, self.G0)
        keep = np.isfinite(mu) & (np.abs(np.imag(mu)) <= 1e-6 * np.maximum(np.abs(mu), 1.0))
        mu, v = np.real(mu[keep]), np.real(v[:, keep])
        order = np.argsort(np.abs(mu))
        mu, v = mu[order], v[:, order]
        if k is not None:
            k = _count(k, len(self.z_labels))
            mu, v = mu[:k], v[:, :k]
        if v.size:
            v = v / np.abs(v).max(axis=0)
        return mu, v, self.DF @ v

    def state_space(self, outputs: str = "z"):
        """(A, B, C, D) of the linearized system in the state [δz; δy^k; δż] with generalized
        forces on z as inputs and, as outputs, δz (``outputs="z"``) or the nodal coordinates
        δx = DF δz (``outputs="x"``; the kinematic coordinates' own effect is not included)."""
        n, k = self.M0.shape[0], len(self.y_labels)
        A = self.state_matrix()
        B = np.vstack([np.zeros((n + k, n)), np.linalg.inv(self.M0)])
        if outputs == "z":
            C = np.hstack([np.eye(n), np.zeros((n, n + k))])
        elif outputs == "x":
            C = np.hstack([self.DF, np.zeros((self.DF.shape[0], n + k))])
        else:
            raise InputError("outputs must be 'z' or 'x'")
        return A, B, C, np.zeros((C.shape[0], n))

    def __repr__(self):
        kind = ", sparse nodal matrices" if "_sim" in self.__dict__ else ""
        return f"<spacar.Linearization at t = {self.t:g}: {len(self.z_labels)} coordinates ({self.n_line} LINE){kind}>"


def _symmetric(a) -> bool:
    return a.size == 0 or np.abs(a - a.T).max() <= 1e-12 * np.abs(a).max()


def _modal_basis(M, K):
    """(ω², Ψ) of K ψ = ω² M ψ with Ψᵀ M Ψ = I, for symmetric M (positive definite) and K; None
    otherwise. From the inverse pencil M φ = (1/ω²) K φ where K is positive definite, whose
    largest eigenvalues, the lowest modes, come with full relative precision."""
    import scipy.linalg

    if not (_symmetric(M) and _symmetric(K)):
        return None
    Ms, Ks = 0.5 * (M + M.T), 0.5 * (K + K.T)
    try:
        nu, phi = scipy.linalg.eigh(Ms, Ks)   # φᵀ K φ = 1, φᵀ M φ = ν
        if np.all(nu > 0):
            return 1.0 / nu, phi / np.sqrt(nu)
    except (np.linalg.LinAlgError, ValueError):
        pass
    try:
        return scipy.linalg.eigh(Ks, Ms)
    except (np.linalg.LinAlgError, ValueError):
        return None


def second_order_eigenvalues(M, D, K):
    """The eigenvalues λ of (λ² M + λ D + K) v = 0 for symmetric M (positive definite) and K, or
    None (then those of the state matrix apply). In the undamped modes Ψ, each mode's
    coordinate scaled by √|ω²|: the matrix [[0, S], [−sign(ω²) S, −Ψᵀ D Ψ]] has the norm of the
    largest ω rather than its square, so that the slow poles keep their relative precision
    (eigvals of [[0, I], [−M⁻¹K, −M⁻¹D]] of a fine mesh lose it: 1e-7 on a 200-beam cantilever);
    without damping ±iω (±√−ω² for unstable modes) directly."""
    basis = _modal_basis(M, K)
    if basis is None:
        return None
    w2, psi = basis
    if not np.any(D):
        root = np.sqrt(np.abs(w2)).astype(complex)
        lam = np.where(w2 >= 0, 1j * root, root)
        return np.concatenate([lam, -lam])
    n = len(w2)
    s = np.sqrt(np.abs(w2))
    s = np.where(s > 0, s, 1.0)
    A = np.block([[np.zeros((n, n)), np.diag(s)], [np.diag(-np.sign(w2) * np.abs(w2) / s), -psi.T @ D @ psi]])
    return np.linalg.eigvals(A)


def _count(k, nz: int) -> int:
    """k, checked: an integer from 1 to nz."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= nz:
        raise InputError(f"k must be an integer from 1 to the number of coordinates ({nz}), got {show(k)}")
    return int(k)


class NodalMatrices:
    """The linearized equations at rest in the nodal coordinates (docs/formulation.md §10), sparse
    (scipy.sparse, over all nx coordinates, those of fixed and input coordinates zero): ``M``
    mass, ``D`` damping (EDAMPP), ``K`` structural stiffness (ESTIFF), ``G`` geometric stiffness
    (the complete stresses and the loads' stiffness); ``A`` the constraint rows (rigid, input and
    LINE-free deformations of the velocity rows that are not degrees of freedom, ∂e/∂x);
    ``E`` the map δz = E δx to the coordinates z of the linearization; ``free`` the indices of
    the free coordinates; ``coordinate_labels`` (node, component) of every coordinate. The reduced
    matrices are Zᵀ M Z etc. with Z = DF (the motions δx = Z δz with A δx = 0); Z is never formed.
    """

    def __init__(self, d: dict, coordinate_labels):
        import scipy.sparse

        for name in ("M", "D", "K", "G", "A", "E", "B", "S", "Dc"):
            setattr(self, name, scipy.sparse.csr_matrix(d[name]))
        self.free = np.asarray(d["free"], dtype=int)
        self.coordinate_labels = list(coordinate_labels)

    def _scatter(self, vf):
        vx = np.zeros((self.M.shape[0],) + vf.shape[1:])
        vx[self.free] = vf
        return vx

    def modes(self, sim, k: int):
        """(ω², shapes in x (nx x k)) of the k lowest |ω²| of (K + G) v = ω² M v on A v = 0, by
        ARPACK in shift-invert mode about 0 (just below 0 if K + G is singular there: rigid-body
        motions), each solve one of the saddle-point system."""
        import scipy.sparse.linalg as sla

        f = self.free
        M = self.M[f][:, f].tocsc()
        sigma = 0.0
        info = sim.nodal_factorize(1.0, 1.0, 0.0, 0.0)
        if info["ok"] and info["singular"]:
            # Rigid-body motions: shift below zero by a small fraction of the stiffness's size.
            sigma = -1e-6 * abs(self.K[f][:, f].diagonal()).max() / max(abs(M.diagonal()).max(), 1e-300)
            info = sim.nodal_factorize(1.0, 1.0, -sigma, 0.0)
        if not info["ok"] or info["singular"]:
            raise SpacarError("the stiffness matrix K0 + G0 - σ M0 of the eigen-analysis is singular or not finite")
        op = sla.LinearOperator(M.shape, matvec=lambda b: _bounded_solve(sim, np.asarray(b, dtype=float).ravel()),
                                dtype=float)
        v0 = sim.nodal_solve(np.ones(M.shape[0]))
        with _arpack("modes", k):
            if info["symmetric"]:
                w2, vf = sla.eigsh(M, k=k, M=M, sigma=sigma, OPinv=op, which="LM", v0=v0)
            else:
                w2, vf = sla.eigs(M, k=k, M=M, sigma=sigma, OPinv=op, which="LM", v0=v0)
                vf = np.real(vf)
        w2 = np.real(w2)
        if info["symmetric"]:
            # The Rayleigh quotients, from the elements' energies (nodal_energies): the shift-invert
            # solves carry the rounding of the assembled matrices of a fine mesh (ε times their
            # condition), the quotients of the vectors they give do not.
            energies = np.array([sim.nodal_energies(vf[:, j]) for j in range(vf.shape[1])]).reshape(-1, 4)
            w2 = (energies[:, 0] + energies[:, 1]) / energies[:, 2]
        order = np.argsort(np.abs(w2))
        return w2[order], self._scatter(vf[:, order])

    def buckling(self, sim, k: int):
        """(μ, shapes in x) of the k smallest |μ| of (K + μ G) v = 0 on A v = 0: the largest
        eigenvalues 1/μ of K⁻¹(−G) (ARPACK), each K⁻¹ a solve of the saddle-point system."""
        import scipy.sparse.linalg as sla

        f = self.free
        G = self.G[f][:, f].tocsc()
        info = sim.nodal_factorize(1.0, 0.0, 0.0, 0.0)
        if not info["ok"] or info["singular"]:
            raise SpacarError("the structural stiffness K0 is singular (a degree of freedom without stiffness): "
                              "the sparse buckling analysis needs a regular K0; use method='dense'")
        op = sla.LinearOperator(G.shape, matvec=lambda b: _bounded_solve(sim, -(G @ np.asarray(b, dtype=float).ravel())),
                                dtype=float)
        with _arpack("buckling modes", k):
            nu, vf = sla.eigs(op, k=k, which="LM", v0=sim.nodal_solve(np.ones(G.shape[0])))
        keep = np.abs(nu) > 0
        real = np.abs(np.imag(nu)) <= 1e-6 * np.abs(nu)
        nu, vf = np.real(nu[keep & real]), np.real(vf[:, keep & real])
        mu = 1.0 / nu
        if info["symmetric"]:  # Rayleigh quotients from the elements' energies, as in modes()
            energies = np.array([sim.nodal_energies(vf[:, j]) for j in range(vf.shape[1])]).reshape(-1, 4)
            mu = -energies[:, 0] / energies[:, 1]
        order = np.argsort(np.abs(mu))
        return mu[order], self._scatter(vf[:, order])



@contextlib.contextmanager
def _arpack(what: str, k: int):
    """ARPACK's failures as a SpacarError that says what to do (its own message names workspace
    sizes): typically fewer finite modes than asked, as when only a few point masses carry mass."""
    import scipy.sparse.linalg as sla

    try:
        yield
    except (sla.ArpackError, sla.ArpackNoConvergence) as err:
        raise SpacarError(f"the sparse eigen-analysis of the {k} lowest {what} failed (ARPACK: {err}); a model with "
                          "few masses (e.g. point masses alone, massless elements) or few loaded elements has "
                          "fewer finite modes than asked: ask for fewer (k), or use method='dense'") from None


def _bounded_solve(sim, b):
    """One solve of ARPACK's shift-invert iteration, within the thread's deadline (a sweep's
    time_limit) and stopped by its cancellation."""
    _core.check_deadline("(in the eigen-analysis)")
    return sim.nodal_solve(b)


def linearize(model, state=None, *, time_limit=None) -> Linearization:
    """Linearized equations of ``model`` at ``state``: None for the model's current state, or
    ``(t, q, qd)`` with the degrees of freedom in their order (DYNX coordinates ascending, then
    DYNE deformations ascending). The mechanism is assembled at the model's current state first
    and then moved continuously to ``state`` (the inputs at time t), so that the calculable
    coordinates stay on the branch of the assembled mechanism. ``time_limit``: wall-clock seconds
    the linearization may take (:class:`spacar.TimeLimitError` beyond; the eigen-analyses of the
    result are later calls, bounded by :func:`spacar.sweep`'s time_limit when it makes them)."""
    with time_limited(time_limit, "in the linearization"):
        return linearized_simulation(model, state)[0]


def linearized_simulation(model, state=None):
    """(Linearization, the simulation moved to the state, (t, q, qd) of the state): what
    :func:`linearize` computes, with the simulation kept for further evaluations about the same
    state (spacar.state_space differentiates the velocities there)."""
    if not isinstance(model, Model):
        raise InputError(f"linearize: model must be a spacar.Model, got {show(model)}")
    sim = _core.Simulation(model.core)  # prepares the model (the first END) and compiles it
    sim.assemble()
    _core.check_deadline("(in the assembly)")
    system = sim.system
    if state is None:
        t, q, qd = model.current_time, system.q0, system.qd0
    else:
        try:
            t, q, qd = state
            t = float(t)
            q = np.asarray(q, dtype=float).reshape(-1)
            qd = np.asarray(qd, dtype=float).reshape(-1)
        except (TypeError, ValueError, OverflowError):
            raise InputError("state must be (t, q, qd): a time and two arrays of numbers") from None
        if not (np.isfinite(t) and np.isfinite(q).all() and np.isfinite(qd).all()):
            raise InputError("state (t, q, qd) must hold finite numbers only (no NaN or infinity)")
    t, q, qd = float(t), np.array(q, dtype=float), np.array(qd, dtype=float)
    if state is None:
        # At rest in static equilibrium: the sparse nodal matrices, the dense ones on first use.
        nodal = sim.linearize_nodal()
        if nodal is not None:
            return (Linearization._from_nodal(nodal, sim, (t, q, qd), system.coord_label, system.def_label), sim,
                    (t, q, qd))
    try:
        sim.move_to(t, q, qd)
    except SingularMassError as err:
        if state is None:  # a structure without masses, for its stiffness: at its static equilibrium
            raise SingularMassError(f"{err}; a model without masses is linearized at a static equilibrium (at rest, "
                                    "its loads balanced): call spacar.static(model) first, which leaves it there") \
                from None
        raise
    return Linearization(sim.linearize(), system.coord_label, system.def_label), sim, (t, q, qd)
