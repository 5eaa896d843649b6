"""Design sensitivities at a static equilibrium (docs/sensitivity.md): the derivatives of the
static displacements, the eigenfrequencies and the compliance with respect to element and node
parameters (ESTIFF, EMASS, MASS values) and cross-section dimensions, by the direct method.

At the equilibrium q(p), R(q(p), p) = 0 for the reduced generalized forces R, so

    dq/dp = −K_T⁻¹ ∂R/∂p,      K_T = ∂R/∂q = K0 + G0,

one solve of the sparse tangent per parameter. A quantity Q(q, p) of the equilibrium (a mode's
stiffness and mass φᵀ K_T φ, φᵀ M0 φ; the compliance) changes by dQ/dp = ∂Q/∂p + ∂Q/∂q · dq/dp.
The partial derivatives in p are taken at the fixed positions of the equilibrium, from the model
with p changed put at the same positions (spacar._core.StaticPoint): there R and the quadratic
forms are affine in an ESTIFF, EMASS or MASS value (the constitutive stresses S ε, the gravity
loads, the masses), so their central difference is exact to rounding; a section dimension enters
nonlinearly (EI ∝ h³), and Richardson's extrapolation of two central differences makes its
error O(h⁴), below 1e-11. ∂Q/∂q · dq/dp, the change of the geometric stiffness and of the
shape of the modes as the equilibrium moves, is a central difference along dq/dp (zero, and
skipped, when the loads do not depend on p, e.g. at an unloaded state). Eigenvalue derivatives
dω²/dp = φᵀ (dK_T/dp − ω² dM0/dp) φ for φᵀ M0 φ = 1 hold for simple eigenvalues.
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

# The relative step of the central differences in a parameter (Richardson: h and h/2).
_STEP = 1e-3
# The step along dq/dp, relative to the model's size (its largest coordinate span).
_STATE_STEP = 1e-5


@dataclass
class Dimension:
    """A cross-section dimension as a design parameter: ``make(value)`` returns the
    :class:`spacar.section.Section` of the ``elements`` (numbers) for a value of the dimension,
    applied to them as :meth:`spacar.section.Section.apply` does with ``rotary`` and ``shear``.
    E.g. the thickness of two leaves: ``Dimension(lambda t: section.rectangle(0.02, t, STEEL),
    0.5e-3, [1, 2, 3, 4])``."""

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
        self.elements = [int(e) for e in self.elements]
        if not self.elements:
            raise InputError("Dimension: name at least one element")


class _Parameter:
    """A parameter: its label, value and how a copy of the model takes another value."""

    def __init__(self, spec, model):
        if isinstance(spec, Dimension):
            self.label, self.value, self.linear = f"{spec.name} of elements {spec.elements}", float(spec.value), False

            def put(m, v, spec=spec):
                spec.make(v).apply(m, *spec.elements, rotary=spec.rotary, shear=spec.shear)
            self.put = put
            return
        try:
            kind, number, index = spec
            kind = str(kind).upper()
            number, index = int(number), int(index)
        except (TypeError, ValueError):
            raise InputError(f"a parameter is ('ESTIFF' | 'EMASS', element, i), ('MASS', node, i) or a "
                             f"spacar.sensitivity.Dimension, got {show(spec)}") from None
        table = model.core.nodes if kind == "MASS" else model.core.elements
        what = "node" if kind == "MASS" else "element"
        if kind not in ("ESTIFF", "EMASS", "MASS"):
            raise InputError(f"a parameter's kind is ESTIFF, EMASS or MASS, got {show(kind)}")
        if number not in table:
            raise InputError(f"{kind} parameter: {what} {number} is not defined")
        values = [float(v) for v in getattr(table[number], kind.lower())]
        # A mass may be added where there is none; a stiffness value must exist (a missing one,
        # e.g. a shear stiffness, means a rigid deformation, which has no derivative).
        if not (1 <= index <= len(values) or (index == 1 and kind != "ESTIFF")):
            raise InputError(f"{kind} parameter: {what} {number} has {len(values)} {kind} values, no value {index}")
        self.label, self.linear = f"{kind} {number} {index}", True
        self.value = float(values[index - 1]) if index <= len(values) else 0.0
        size = max([abs(float(v)) for v in values] + [0.0])
        self.scale = abs(self.value) or size or 1.0
        setter = {"ESTIFF": "estiff", "EMASS": "emass", "MASS": "mass"}[kind]

        def put(m, v, values=values, index=index, number=number, setter=setter):
            new = [float(a) for a in values] + [0.0] * (index - len(values))
            new[index - 1] = v
            getattr(m, setter)(number, *new)
        self.put = put

    def step(self) -> float:
        return _STEP * (abs(self.value) or getattr(self, "scale", 1.0))


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
        except (AttributeError, IndexError, TypeError):
            raise InputError("sensitivity: results must be the static results of the model (spacar.static)") from None
        self.point = _core.StaticPoint(self.model.core, self.x, self.e)
        self.q0 = np.array(self.point.q)
        if self.q0.size == 0:
            raise InputError("sensitivity: the model has no degrees of freedom: nothing moves with a parameter")
        spans = [np.ptp(self.x)] if self.x.size else [1.0]
        self.size = float(max(spans + [1e-300]))

    def at(self, parameter: _Parameter, value: float):
        m = self.model.copy()
        parameter.put(m, value)
        return _core.StaticPoint(m.core, self.x, self.e)

    def partial(self, parameter: _Parameter, quantity):
        """∂quantity(point)/∂p at the fixed positions: a central difference (exact for a quantity
        affine in p), with Richardson's extrapolation when p enters nonlinearly."""
        h, p = parameter.step(), parameter.value

        def central(step):
            return (np.asarray(quantity(self.at(parameter, p + step))) -
                    np.asarray(quantity(self.at(parameter, p - step)))) / (2.0 * step)
        coarse = central(h)
        if parameter.linear:
            return coarse
        return (4.0 * central(h / 2.0) - coarse) / 3.0

    def dq(self, parameter: _Parameter) -> np.ndarray:
        """dq/dp = −K_T⁻¹ ∂R/∂p of the equilibrium."""
        dR = self.partial(parameter, lambda pt: np.array(pt.residual))
        if not np.any(dR):
            return np.zeros_like(self.q0)
        return -np.asarray(self.point.solve(dR))

    def along(self, dq, quantity):
        """∂quantity/∂q · dq at the equilibrium by a central difference along dq (the model
        unchanged); zero for dq = 0."""
        if not np.any(dq):
            return 0.0
        t = _STATE_STEP * self.size / np.abs(dq).max()
        mover = _core.StaticPoint(self.model.core, self.x, self.e)
        values = []
        for s in (t, -t):
            mover.move_to(self.q0 + s * dq)
            values.append(np.asarray(quantity(mover)))
        return (values[0] - values[1]) / (2.0 * t)


def _parameters(parameters, model):
    if isinstance(parameters, (tuple, Dimension)) and (isinstance(parameters, Dimension) or
                                                       (parameters and isinstance(parameters[0], str))):
        parameters = [parameters]
    try:
        specs = list(parameters)
    except TypeError:
        raise InputError(f"parameters must be a list of parameters, got {show(parameters)}") from None
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
        dq = np.column_stack([eq.dq(p) for p in params])
        dx = np.column_stack([eq.point.motion(dq[:, j]) for j in range(len(params))])
    labels = [tuple(int(v) for v in c) for c in _core.Simulation(eq.model.core).system.coord_label]
    return DisplacementSensitivity(q=eq.q0, dq=dq, x=eq.x, dx=dx, labels=[p.label for p in params],
                                   coordinate_labels=labels)


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
    """The k lowest eigenfrequencies of ``model`` at its static equilibrium and their derivatives
    with respect to ``parameters`` (as :func:`displacements`): dω²/dp = φᵀ (dK_T/dp − ω² dM0/dp) φ
    for each mode φ (φᵀ M0 φ = 1), K_T = K0 + G0 with the geometric stiffness of the loads, its
    change with the equilibrium included. Simple eigenvalues only: the derivative of a repeated
    one depends on the direction of the change (a :class:`spacar.SpacarError` names the pair)."""
    from .linearize import linearize

    if isinstance(k, bool) or not isinstance(k, numbers.Integral) or k < 1:
        raise InputError(f"k must be a positive integer, got {show(k)}")
    with time_limited(time_limit, "in the sensitivity analysis"):
        eq = _Equilibrium(model, results)
        params = _parameters(parameters, eq.model)
        lin = linearize(eq.model)
        if lin.n_line:
            raise InputError("frequency sensitivities of a linearization with LINE parameters are not supported")
        k = min(int(k), eq.q0.size)
        _, shapes, _ = lin.mode_shapes(k if k < eq.q0.size - 1 else None)
        shapes = np.asarray(shapes)[:, :k]
        forms = np.array([_mode_forms(eq.point, shapes[:, i]) for i in range(shapes.shape[1])])
        if np.any(forms[:, 1] <= 0):
            raise SpacarError("a mode has no mass (φᵀ M0 φ = 0): its frequency is infinite")
        shapes = shapes / np.sqrt(forms[:, 1])
        w2 = forms[:, 0] / forms[:, 1]
        order = np.argsort(w2)
        w2, shapes = w2[order], shapes[:, order]
        close = np.nonzero(np.abs(np.diff(w2)) <= 1e-8 * np.abs(w2[1:]))[0]
        if close.size:
            i = int(close[0])
            raise SpacarError(f"modes {i + 1} and {i + 2} have the same frequency ({np.sqrt(abs(w2[i])) / 2 / np.pi:.6g} "
                              "Hz): the derivative of a repeated eigenvalue is not defined; ask for fewer modes (k)")

        def all_forms(point):
            return np.array([_mode_forms(point, shapes[:, i]) for i in range(shapes.shape[1])])
        dw2 = np.empty((len(w2), len(params)))
        for j, p in enumerate(params):
            d = eq.partial(p, all_forms) + eq.along(eq.dq(p), all_forms)
            dw2[:, j] = d[:, 0] - w2 * d[:, 1]
    f = np.sign(w2) * np.sqrt(np.abs(w2)) / (2 * np.pi)
    # df/dp = dω²/dp / (8π² f)
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
    if isinstance(node, bool) or not isinstance(node, numbers.Integral):
        raise InputError(f"node must be a node number, got {show(node)}")
    nodes = [int(node)]
    with time_limited(time_limit, "in the sensitivity analysis"):
        eq = _Equilibrium(model, results)
        params = _parameters(parameters, eq.model)
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

        def compliance_at(point):
            return np.asarray(point.compliance(nodes)[0])
        dC = np.empty((len(params), m, m))
        for j, p in enumerate(params):
            dC[j] = -eq.partial(p, bilinear) + eq.along(eq.dq(p), compliance_at)
    return ComplianceSensitivity(C=C, dC=dC, labels=[p.label for p in params])
