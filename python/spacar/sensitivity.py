"""Design sensitivities at a static equilibrium (docs/sensitivity.md): the derivatives of the
static displacements, the eigenfrequencies and the compliance with respect to element and node
parameters (ESTIFF, EMASS, MASS values) and cross-section dimensions, by the direct method.

At the equilibrium q(p), R(q(p), p) = 0 for the reduced generalized forces R, so

    dq/dp = −K_T⁻¹ ∂R/∂p,      K_T = ∂R/∂q = K0 + G0,

one solve of the sparse tangent per parameter. A quantity Q(q, p) of the equilibrium (a mode's
stiffness and mass φᵀ K_T φ, φᵀ M0 φ; the compliance) changes by dQ/dp = ∂Q/∂p + ∂Q/∂q · dq/dp.
The partial derivatives in p are taken at the fixed positions of the equilibrium, from the model
with p changed put at the same positions (spacar._core.StaticPoint; a parameter does not change
the kinematics). There R and the quadratic forms are affine in an EMASS or MASS value (the
masses, the gravity loads), so one difference is exact to rounding; a stiffness or a section
dimension may enter nonlinearly (a shear-flexible beam's S ∝ EI/(1 + 12EI/kGAl²), EI ∝ t³), and
Richardson's extrapolation of two central differences makes the error O(h⁴), below 1e-11.
∂Q/∂q · dq/dp, the change of the geometric stiffness and of the shape of the modes as the
equilibrium moves, is a central difference along dq/dp, each DOF moved by 1e-6 of its size
(skipped when the loads do not depend on p, e.g. at an unloaded state). The eigenvalue and
compliance derivatives take a symmetric tangent and simple eigenvalues; a tangent made
unsymmetric by TORQUEL or TORQUEG, and repeated eigenvalues, are refused.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass

import numpy as np

from . import _core
from ._util import show, time_limited
from .errors import InputError, SpacarError
from .model import Model

__all__ = ["Dimension", "compliance", "displacements", "frequencies"]

# The relative step of the differences in a parameter (Richardson: h and h/2).
_STEP = 1e-3
# The step along dq/dp: the largest DOF moves by this fraction of its size (the mean element
# length for lengths, 1 rad for angles).
_STATE_STEP = 1e-6
# A residual at the equilibrium given, relative to the loads it balances, that is one.
_EQUILIBRIUM = 1e-7


@dataclass
class Dimension:
    """A cross-section dimension as a design parameter: ``make(value)`` returns the
    :class:`spacar.section.Section` of the ``elements`` (numbers) for a value of the dimension,
    applied to them as :meth:`spacar.section.Section.apply` does with ``rotary`` and ``shear``.
    E.g. the thickness of two leaves: ``Dimension(lambda t: section.rectangle(0.02, t, STEEL),
    0.5e-3, [1, 2, 3, 4])``. The model must have that section at ``value`` (checked)."""

    make: object
    value: float
    elements: list
    rotary: bool = True
    shear: bool = False
    name: str = "dimension"

    def __post_init__(self):
        if not callable(self.make):
            raise InputError(f"Dimension: make must be a function of the dimension, got {show(self.make)}")
        if isinstance(self.value, bool) or not isinstance(self.value, numbers.Real) or not np.isfinite(self.value) \
                or self.value <= 0:
            raise InputError(f"Dimension: value must be a positive number, got {show(self.value)}")
        elements = [self.elements] if isinstance(self.elements, numbers.Integral) else self.elements
        try:
            elements = list(elements)
        except TypeError:
            elements = None
        if not elements or not all(_whole(e) for e in elements):
            raise InputError(f"Dimension: elements must be element numbers, got {show(self.elements)}")
        self.elements = [int(e) for e in elements]

    def section(self, value):
        from .section import Section

        made = self.make(value)
        if not isinstance(made, Section):
            raise InputError(f"Dimension {self.name}: make({value:g}) must return a spacar.section.Section, got "
                             f"{show(made)}")
        return made


def _whole(v) -> bool:
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


class _Parameter:
    """A parameter: its label, value, how a copy of the model takes another value, and whether
    the quantities are affine in it at fixed positions (one difference then is exact)."""

    def __init__(self, spec, model):
        if isinstance(spec, Dimension):
            self.label, self.value, self.linear = f"{spec.name} of elements {spec.elements}", float(spec.value), False
            self.h = _STEP * self.value

            def put(m, v, spec=spec):
                spec.section(v).apply(m, *spec.elements, rotary=spec.rotary, shear=spec.shear)
            self.put = put
            self._check_dimension(spec, model)
            return
        ok = isinstance(spec, (tuple, list)) and len(spec) == 3 and isinstance(spec[0], str) \
            and _whole(spec[1]) and _whole(spec[2])
        if not ok:
            raise InputError(f"a parameter is ('ESTIFF' | 'EMASS', element, i), ('MASS', node, i) with whole "
                             f"numbers, or a spacar.sensitivity.Dimension; got {show(spec)}")
        kind, number, index = spec[0].upper(), int(spec[1]), int(spec[2])
        if kind not in ("ESTIFF", "EMASS", "MASS"):
            raise InputError(f"a parameter's kind is ESTIFF, EMASS or MASS, got {show(spec[0])}")
        table = model.core.nodes if kind == "MASS" else model.core.elements
        what = "node" if kind == "MASS" else "element"
        if number not in table:
            raise InputError(f"{kind} parameter: {what} {number} is not defined")
        values = [float(v) for v in getattr(table[number], kind.lower())]
        # A mass may be added where there is none; a stiffness value must exist and not be zero
        # (a missing or zero one, e.g. a shear stiffness, means a rigid deformation).
        if not (1 <= index <= len(values) or (index == 1 and kind != "ESTIFF")):
            raise InputError(f"{kind} parameter: {what} {number} has {len(values)} {kind} values, no value {index}")
        self.label = f"{kind} {number} {index}"
        self.value = values[index - 1] if index <= len(values) else 0.0
        if kind == "ESTIFF" and self.value == 0.0:
            raise InputError(f"{self.label}: a zero stiffness value means a rigid (or absent) deformation, which has "
                             "no derivative")
        # Masses enter affinely: one forward difference, from any value (0 too). Stiffnesses may
        # not (a shear-flexible beam's bending): central differences, extrapolated.
        self.linear = kind != "ESTIFF"
        size = max([abs(v) for v in values] + [0.0])
        self.h = _STEP * (abs(self.value) or size or 1.0)
        setter = kind.lower()

        def put(m, v, values=values, index=index, number=number, setter=setter):
            new = values + [0.0] * (index - len(values))
            new[index - 1] = v
            getattr(m, setter)(number, *new)
        self.put = put

    @staticmethod
    def _check_dimension(spec, model):
        """The model must have the Dimension's section at its value on its elements."""
        trial = model.copy()
        spec.section(spec.value).apply(trial, *spec.elements, rotary=spec.rotary, shear=spec.shear)
        for e in spec.elements:
            for field in ("estiff", "emass"):
                have = np.array(getattr(model.core.elements[e], field), dtype=float)
                want = np.array(getattr(trial.core.elements[e], field), dtype=float)
                if have.shape != want.shape or not np.allclose(have, want, rtol=1e-9, atol=0.0):
                    raise InputError(f"Dimension {spec.name}: element {e}'s {field.upper()} {have.tolist()} is not the "
                                     f"section's at {spec.value:g} ({want.tolist()}; rotary={spec.rotary}, "
                                     f"shear={spec.shear}): the derivative would be of another model")


class _Equilibrium:
    """The equilibrium of the model and the points of the model with a parameter changed there."""

    def __init__(self, model, results):
        if not isinstance(model, Model):
            raise InputError(f"sensitivity: model must be a spacar.Model, got {show(model)}")
        from .statics import static

        if results is None:
            self.model = model.copy()
            results = static(self.model)
        else:
            self.model = model
        try:
            self.x, self.e = np.array(results.x[-1], dtype=float), np.array(results.e[-1], dtype=float)
        except (AttributeError, IndexError, TypeError, ValueError):
            raise InputError("sensitivity: results must be the static results of the model (spacar.static)") from None
        self.point = _core.StaticPoint(self.model.core, self.x, self.e)
        # R in units of energy (a length DOF's force times its size), as the load scale and the
        # static solve's tolerance are.
        residual = np.abs(np.asarray(self.point.residual) * np.asarray(self.point.dof_scale)).max(initial=0.0)
        if residual > _EQUILIBRIUM * self.point.load_scale:
            raise InputError(f"sensitivity: the results' last row is not a static equilibrium of this model (residual "
                             f"{residual:.3g} against loads of {self.point.load_scale:.3g}): pass the results of "
                             "spacar.static(model) with the model left there, or results=None")
        self.q0 = np.array(self.point.q)
        if self.q0.size == 0:
            raise InputError("sensitivity: the model has no degrees of freedom: nothing moves with a parameter")
        self.dof_scale = np.array(self.point.dof_scale)

    def at(self, parameter: _Parameter, value: float):
        m = self.model.copy()
        parameter.put(m, value)
        return _core.StaticPoint(m.core, self.x, self.e)

    def partial(self, parameter: _Parameter, quantity):
        """∂quantity(point)/∂p at the fixed positions, quantity a tuple of arrays: one forward
        difference when p enters affinely, else central differences extrapolated (Richardson)."""
        h, p = parameter.h, parameter.value

        def values(point):
            return tuple(np.asarray(v, dtype=float) for v in quantity(point))
        if parameter.linear:
            base, moved = values(self.point), values(self.at(parameter, p + h))
            return tuple((b - a) / h for a, b in zip(base, moved))

        def central(step):
            plus, minus = values(self.at(parameter, p + step)), values(self.at(parameter, p - step))
            return tuple((a - b) / (2.0 * step) for a, b in zip(plus, minus))
        coarse, fine = central(h), central(h / 2.0)
        return tuple((4.0 * f - c) / 3.0 for c, f in zip(coarse, fine))

    def dq(self, dR) -> np.ndarray:
        """dq/dp = −K_T⁻¹ ∂R/∂p of the equilibrium."""
        if not np.any(dR):
            return np.zeros_like(self.q0)
        return -np.asarray(self.point.solve(dR))

    def along(self, dq, quantity):
        """∂quantity/∂q · dq at the equilibrium by a central difference along dq (the model
        unchanged), the largest DOF moved by _STATE_STEP of its size; zero for dq = 0."""
        if not np.any(dq):
            return 0.0
        t = _STATE_STEP / np.abs(dq / self.dof_scale).max()
        mover = _core.StaticPoint(self.model.core, self.x, self.e)
        values = []
        for s in (t, -t):
            mover.move_to(self.q0 + s * dq)
            values.append(np.asarray(quantity(mover)))
        return (values[0] - values[1]) / (2.0 * t)

    def require_symmetric(self, what: str):
        if not self.point.symmetric():
            raise InputError(f"sensitivity.{what}: the tangent stiffness is not symmetric (the load stiffness of "
                             "TORQUEL or TORQUEG): its eigenvalue and compliance derivatives need the left vectors, "
                             "which are not computed; sensitivity.displacements applies")


def _parameters(parameters, model):
    single = isinstance(parameters, Dimension) or (isinstance(parameters, (tuple, list)) and len(parameters) == 3
                                                   and isinstance(parameters[0], str))
    specs = [parameters] if single else parameters
    if isinstance(specs, (str, bytes)) or not hasattr(specs, "__iter__"):
        raise InputError(f"parameters must be a list of parameters, got {show(parameters)}")
    specs = list(specs)
    if not specs:
        raise InputError("name at least one parameter")
    return [_Parameter(s, model) for s in specs]


@dataclass
class DisplacementSensitivity:
    """``dq`` (n_dof x n_par): dq/dp of the degrees of freedom; ``dx`` (nx x n_par): dx/dp of every
    coordinate; ``labels``: the parameters; ``coordinate_labels``: (node, component) of the rows of
    dx. :meth:`node` gives a node's rows."""

    q: np.ndarray
    dq: np.ndarray
    x: np.ndarray
    dx: np.ndarray
    labels: list
    coordinate_labels: list

    def node(self, n: int) -> np.ndarray:
        """dx/dp of node n's coordinates (components x n_par)."""
        rows = [i for i, (node, _) in enumerate(self.coordinate_labels) if node == n]
        if not rows:
            raise InputError(f"node {show(n)} has no coordinates in the model")
        return self.dx[rows]


def displacements(model, parameters, *, results=None, time_limit=None) -> DisplacementSensitivity:
    """The derivatives of the static equilibrium of ``model`` with respect to ``parameters``
    (a list of ``("ESTIFF", element, i)``, ``("EMASS", element, i)``, ``("MASS", node, i)`` and
    :class:`Dimension`): dq/dp = −K_T⁻¹ ∂R/∂p, exact at the equilibrium (a large deflection
    too), and dx/dp = DF_q dq/dp of every coordinate. ``results``: the model's static results
    (``spacar.static(model)``, the model left at their last row); None solves the equilibrium
    of a copy. ``time_limit``: seconds for the whole analysis."""
    with time_limited(time_limit, "in the sensitivity analysis"):
        eq = _Equilibrium(model, results)
        params = _parameters(parameters, eq.model)
        dq = np.column_stack([eq.dq(eq.partial(p, _residual)[0]) for p in params])
        dx = np.column_stack([eq.point.motion(dq[:, j]) for j in range(len(params))])
        labels = [tuple(int(v) for v in c) for c in eq.point.coordinate_labels]
    return DisplacementSensitivity(q=eq.q0, dq=dq, x=eq.x, dx=dx, labels=[p.label for p in params],
                                   coordinate_labels=labels)


def _residual(point):
    return (np.array(point.residual),)


@dataclass
class FrequencySensitivity:
    """``frequencies`` (Hz, the k lowest) and ``df`` (k x n_par): their derivatives in Hz per unit
    of each parameter; ``dw2``: those of ω² (rad²/s²); ``shapes``: the modes in the DOFs (columns,
    φᵀ M0 φ = 1); ``labels``: the parameters."""

    frequencies: np.ndarray
    df: np.ndarray
    dw2: np.ndarray
    shapes: np.ndarray
    labels: list


def _mode_forms(point, phi):
    k, g, m, _ = point.energies(phi)
    return np.array([k + g, m])


def frequencies(model, parameters, k: int = 6, *, results=None, time_limit=None) -> FrequencySensitivity:
    """The k lowest eigenfrequencies of ``model`` at its static equilibrium (sorted by |ω²| as
    :meth:`spacar.Linearization.eigenfrequencies`) and their derivatives with respect to
    ``parameters`` (as :func:`displacements`): dω²/dp = φᵀ (dK_T/dp − ω² dM0/dp) φ for each mode φ
    (φᵀ M0 φ = 1), K_T = K0 + G0 with the geometric stiffness of the loads, its change with the
    equilibrium included. Simple eigenvalues only: the derivative of a repeated one depends on
    the direction of the change, and a :class:`spacar.SpacarError` names the pair (the k-th mode
    and the next one included); a symmetric tangent (no TORQUEL, TORQUEG)."""
    from .linearize import linearize

    if not _whole(k) or k < 1:
        raise InputError(f"k must be a positive integer, got {show(k)}")
    with time_limited(time_limit, "in the sensitivity analysis"):
        eq = _Equilibrium(model, results)
        params = _parameters(parameters, eq.model)
        eq.require_symmetric("frequencies")
        lin = linearize(eq.model)
        if lin.n_line:
            raise InputError("frequency sensitivities of a linearization with LINE parameters are not supported")
        n = eq.q0.size
        if k > n:
            raise InputError(f"k = {k} modes asked for, the model has {n} degrees of freedom")
        # One mode more than asked (where there is one), to see a k-th eigenvalue repeated.
        wanted = min(k + 1, n)
        f_all, shapes, _ = lin.mode_shapes(wanted if wanted < n - 1 else None)
        f_all, shapes = np.asarray(f_all)[:wanted], np.asarray(shapes)[:, :wanted]
        if not np.all(np.isfinite(f_all[:k])):
            i = int(np.nonzero(~np.isfinite(f_all[:k]))[0][0])
            raise SpacarError(f"mode {i + 1} has no mass (an infinite frequency): ask for fewer modes (k ≤ {i})")
        forms = np.array([_mode_forms(eq.point, shapes[:, i]) for i in range(shapes.shape[1])])
        w2 = forms[:, 0] / forms[:, 1]
        order = np.argsort(np.abs(w2), kind="stable")
        w2, forms, shapes = w2[order], forms[order], shapes[:, order]
        close = np.nonzero(np.abs(np.diff(w2)) <= 1e-8 * np.abs(w2[1:]))[0]
        close = close[close < k]
        if close.size:
            i = int(close[0])
            below = f"ask for the modes below the pair (k ≤ {i}) or" if i else "no mode lies below the pair:"
            raise SpacarError(f"modes {i + 1} and {i + 2} have the same frequency ({np.sqrt(abs(w2[i])) / 2 / np.pi:.6g} "
                              f"Hz): the derivative of a repeated eigenvalue is not defined; {below} break the "
                              "symmetry")
        w2, forms, shapes = w2[:k], forms[:k], shapes[:, :k] / np.sqrt(forms[:k, 1])

        def all_forms(point):
            return (np.array([_mode_forms(point, shapes[:, i]) for i in range(k)]),)

        def both(point):
            return _residual(point) + all_forms(point)
        dw2 = np.empty((k, len(params)))
        for j, p in enumerate(params):
            dR, d = eq.partial(p, both)
            d = d + eq.along(eq.dq(dR), lambda point: all_forms(point)[0])
            dw2[:, j] = d[:, 0] - w2 * d[:, 1]
    f = np.sign(w2) * np.sqrt(np.abs(w2)) / (2 * np.pi)
    # df/dp = dω²/dp / (8π² |f|)
    df = dw2 / (8 * np.pi**2 * np.where(f == 0, np.inf, np.abs(f)))[:, None]
    return FrequencySensitivity(frequencies=f, df=df, dw2=dw2, shapes=shapes, labels=[p.label for p in params])


@dataclass
class ComplianceSensitivity:
    """``C``: the compliance at the node (its coordinates; a LAMBDA node's rotation vector) at the
    static equilibrium; ``dC`` (n_par x m x m): its derivatives; ``labels``: the parameters."""

    C: np.ndarray
    dC: np.ndarray
    labels: list


def compliance(model, node, parameters, *, results=None, time_limit=None) -> ComplianceSensitivity:
    """The static compliance at ``node`` (as :func:`spacar.compliance`) of ``model`` at its static
    equilibrium and its derivatives with respect to ``parameters`` (as :func:`displacements`):
    dC/dp = −Uᵀ (∂K_T/∂p) U at the fixed equilibrium (U = K_T⁻¹ DF_qᵀ Tᵀ, the DOFs' response to
    unit loads at the node) plus its change as the equilibrium moves."""
    if not _whole(node):
        raise InputError(f"node must be a node number, got {show(node)}")
    nodes = [int(node)]
    with time_limited(time_limit, "in the sensitivity analysis"):
        eq = _Equilibrium(model, results)
        params = _parameters(parameters, eq.model)
        eq.require_symmetric("compliance")
        C, U = (np.asarray(a) for a in eq.point.compliance(nodes))
        m = C.shape[0]

        def bilinear(point):
            # uᵢᵀ K_T uⱼ by polarization of the quadratic forms, for all pairs.
            out = np.empty((m, m))
            for i in range(m):
                for j in range(i, m):
                    plus, minus = point.energies(U[:, i] + U[:, j]), point.energies(U[:, i] - U[:, j])
                    out[i, j] = out[j, i] = (plus[0] + plus[1] - minus[0] - minus[1]) / 4.0
            return out

        def both(point):
            return _residual(point) + (bilinear(point),)

        def compliance_at(point):
            return np.asarray(point.compliance(nodes)[0])
        dC = np.empty((len(params), m, m))
        for j, p in enumerate(params):
            dR, dK = eq.partial(p, both)
            dC[j] = -dK + eq.along(eq.dq(dR), compliance_at)
    return ComplianceSensitivity(C=C, dC=dC, labels=[p.label for p in params])
