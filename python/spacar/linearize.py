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

import numpy as np

from . import _core
from ._util import show
from .errors import InputError
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

    @property
    def stiffness(self) -> np.ndarray:
        """K0 + N0 + G0."""
        return self.K0 + self.N0 + self.G0

    @property
    def damping(self) -> np.ndarray:
        """C0 + D0."""
        return self.C0 + self.D0

    def _undamped(self):
        import scipy.linalg  # lazily: `import spacar` stays light

        w2, v = scipy.linalg.eig(self.stiffness, self.M0)
        w2 = np.real_if_close(w2, tol=1e6)
        order = np.argsort(np.abs(w2))
        return np.real(w2[order]), v[:, order]

    def eigenfrequencies(self) -> np.ndarray:
        """Undamped eigenfrequencies in Hz, sorted, from (K0 + N0 + G0) v = ω² M0 v. An unstable
        mode (ω² < 0) is returned as a negative number −√|ω²|/2π."""
        w2, _ = self._undamped()
        return np.sign(w2) * np.sqrt(np.abs(w2)) / (2 * np.pi)

    def mode_shapes(self):
        """(frequencies in Hz, shapes in z (nz x nmodes), shapes in the nodal coordinates
        (nx x nmodes)). Each shape in z is normalised to unit largest component (sign
        arbitrary); the nodal shapes are DF times the same vectors, so both describe the same
        motion (their largest component is generally not 1)."""
        w2, v = self._undamped()
        v = np.real(v)
        if v.size:
            v = v / np.abs(v).max(axis=0)
        return np.sign(w2) * np.sqrt(np.abs(w2)) / (2 * np.pi), v, self.DF @ v

    def state_matrix(self) -> np.ndarray:
        """A of d/dt [δz; δy^k; δż] = A [δz; δy^k; δż] (formulation.md §7.3); without
        nonholonomic constraints just d/dt [δz; δż]."""
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
        lam = np.linalg.eigvals(self.state_matrix())
        return lam[np.lexsort((lam.real, np.abs(lam.imag)))]

    def buckling_factors(self) -> np.ndarray:
        """Load multipliers μ of (K0 + μ G0) v = 0 for a static state, sorted by |μ|; only the
        finite ones."""
        import scipy.linalg

        mu = scipy.linalg.eigvals(-self.K0, self.G0)
        mu = mu[np.isfinite(mu)]
        mu = np.real_if_close(mu, tol=1e6)
        return np.real(mu[np.argsort(np.abs(mu))]) if np.isrealobj(mu) else mu[np.argsort(np.abs(mu))]

    def buckling_modes(self):
        """(μ, shapes in z (nz x n), shapes in the nodal coordinates (nx x n)) of
        (K0 + μ G0) v = 0: the real, finite buckling factors sorted by |μ| (as
        :meth:`buckling_factors`, complex ones left out) with their mode shapes, each normalised
        to unit largest component in z (sign arbitrary); the nodal shapes are DF v, drawable with
        ``spacar.draw(res, mode=shapes_x[:, i])``."""
        import scipy.linalg

        mu, v = scipy.linalg.eig(-self.K0, self.G0)
        keep = np.isfinite(mu) & (np.abs(np.imag(mu)) <= 1e-6 * np.maximum(np.abs(mu), 1.0))
        mu, v = np.real(mu[keep]), np.real(v[:, keep])
        order = np.argsort(np.abs(mu))
        mu, v = mu[order], v[:, order]
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
        return f"<spacar.Linearization at t = {self.t:g}: {len(self.z_labels)} coordinates ({self.n_line} LINE)>"


def linearize(model, state=None) -> Linearization:
    """Linearized equations of ``model`` at ``state``: None for the model's current state, or
    ``(t, q, qd)`` with the degrees of freedom in their order (DYNX coordinates ascending, then
    DYNE deformations ascending). The mechanism is assembled at the model's current state first
    and then moved continuously to ``state`` (the inputs at time t), so that the calculable
    coordinates stay on the branch of the assembled mechanism."""
    return linearized_simulation(model, state)[0]


def linearized_simulation(model, state=None):
    """(Linearization, the simulation moved to the state, (t, q, qd) of the state): what
    :func:`linearize` computes, with the simulation kept for further evaluations about the same
    state (spacar.state_space differentiates the velocities there)."""
    if not isinstance(model, Model):
        raise InputError(f"linearize: model must be a spacar.Model, got {show(model)}")
    sim = _core.Simulation(model.core)  # prepares the model (the first END) and compiles it
    sim.assemble()
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
    sim.move_to(t, q, qd)
    return Linearization(sim.linearize(), system.coord_label, system.def_label), sim, (t, q, qd)
