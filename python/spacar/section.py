"""Cross-sections of beams and trusses: the ESTIFF and EMASS values from the dimensions and the
material, the section moduli, and the largest stresses of a solution (docs/statics.md,
"Cross-sections and stresses")::

    steel = spacar.section.STEEL                      # E = 210 GPa, ν = 0.3, ρ = 7850 kg/m³
    leaf = spacar.section.rectangle(b=0.02, h=0.0005, material=steel)
    leaf.apply(model, 1, 2, 3)                        # ESTIFF (and EMASS if ρ > 0) of elements 1–3
    leaf.plbeam_estiff()                              # (EA, EI)
    s = spacar.section.stresses(res, leaf)            # largest normal and shear stress per element
    s.normal.max(), s.element(2).normal

Axes (those of the beam elements, formulation §4.2, §4.8): x along the beam, y the first
principal axis of the cross-section (BEAM: the LGEOMY/definition-line vector; PLBEAM: the
in-plane normal), z = x × y (PLBEAM: out of the plane). ``Iz = ∫y² dA`` resists bending about z,
which is the in-plane bending of PLBEAM (its EI) and the BEAM's ``EIz``; ``Iy = ∫z² dA`` goes
with the BEAM's ``EIy``. Units are the user's (SI in the named materials).
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from ._util import show
from .errors import InputError


def _positive(value, name: str, zero: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value) or \
            not (value >= 0 if zero else value > 0):
        raise InputError(f"{name} must be a {'non-negative' if zero else 'positive'} number, got {show(value)}")
    return float(value)


class Material:
    """A linear elastic isotropic material: Young's modulus ``E``, the shear modulus ``G`` given
    directly or by Poisson's ratio ``nu`` (G = E / 2(1 + ν)), and the density ``rho`` (0: no
    mass)."""

    def __init__(self, E, *, nu=None, G=None, rho=0.0, name: str = ""):
        self.E = _positive(E, "E")
        if (nu is None) == (G is None):
            raise InputError("give the material either Poisson's ratio nu or the shear modulus G")
        if G is None:
            if isinstance(nu, bool) or not isinstance(nu, numbers.Real) or not -1.0 < nu < 0.5:
                raise InputError(f"Poisson's ratio nu must be a number between -1 and 0.5, got {show(nu)}")
            G = self.E / (2.0 * (1.0 + nu))
        self.G = _positive(G, "G")
        self.nu = self.E / (2.0 * self.G) - 1.0
        self.rho = _positive(rho, "rho", zero=True)
        self.name = str(name)

    def __repr__(self):
        return f"<spacar.section.Material {self.name or ''}: E = {self.E:g}, G = {self.G:g}, rho = {self.rho:g}>"


STEEL = Material(210e9, nu=0.3, rho=7850.0, name="steel")
ALUMINIUM = Material(70e9, nu=0.33, rho=2700.0, name="aluminium")
TITANIUM = Material(114e9, nu=0.34, rho=4430.0, name="titanium (Ti-6Al-4V)")


class Section:
    """The properties of one cross-section (made by :func:`rectangle`, :func:`circle`,
    :func:`tube`): area ``A``, second moments ``Iy``, ``Iz`` and polar ``Ip = Iy + Iz``, the
    torsion constant ``J`` (Saint-Venant; ``Ip`` for round sections), the section moduli ``Wy``,
    ``Wz`` (bending stress |M|/W) and ``Wt`` (torsion: τ = |T|/Wt), the transverse shear factor
    ``shear_factor`` (largest shear stress k V / A), the warping constant ``Iw`` (BEAMW's EIw:
    b³h³/144 for a rectangle, as SPACAR Light gives it; 0 for round sections, which do not
    warp), and the ``material`` (None: geometry only)."""

    def __init__(self, shape: str, dims: dict, material, *, A, Iy, Iz, J, Wy, Wz, Wt, shear_factor, round_: bool,
                 Iw: float = 0.0):
        if material is not None and not isinstance(material, Material):
            raise InputError(f"material must be a spacar.section.Material, got {show(material)}")
        self.shape, self.dims, self.material = shape, dims, material
        self.A, self.Iy, self.Iz, self.Ip, self.J, self.Iw = A, Iy, Iz, Iy + Iz, J, Iw
        self.Wy, self.Wz, self.Wt = Wy, Wz, Wt
        self.shear_factor = shear_factor
        self._round = round_  # bending about any axis has the same modulus: |M| = hypot(My, Mz)
        self.principal_angle = 0.0  # from the section's y to its principal y (an angle's legs are not principal)

    # --- the element data ---------------------------------------------------------------------

    def _mat(self) -> Material:
        if self.material is None:
            raise InputError(f"the {self.shape} section has no material: give material=... to know E, G, rho")
        return self.material

    def truss_estiff(self) -> tuple:
        """ESTIFF of PLTRUSS/TRUSS: (EA,)."""
        return (self._mat().E * self.A,)

    def shear_coefficient(self) -> float:
        """Timoshenko's shear coefficient k of the section (the shear stiffness is k G A), Cowper's
        (1966) values for the material's Poisson ratio ν: rectangle 10(1 + ν)/(12 + 11ν), circle
        6(1 + ν)/(7 + 6ν), tube of inner to outer diameter m
        6(1 + ν)(1 + m²)² / ((7 + 6ν)(1 + m²)² + (20 + 12ν) m²) (the same for both axes); an
        I-section the web's share of the area, hw tw / A."""
        nu = self._mat().nu
        if self.shape == "rectangle":
            return 10 * (1 + nu) / (12 + 11 * nu)
        if self.shape in ("I-section", "channel"):  # the web carries the shear
            return 1.0 / self.shear_factor
        if self.shape == "angle":
            return sum(self.shear_areas()) / (2 * self.A)
        if self.shape == "circle":
            return 6 * (1 + nu) / (7 + 6 * nu)
        m2 = ((self.dims["d"] - 2 * self.dims["t"]) / self.dims["d"]) ** 2
        return 6 * (1 + nu) * (1 + m2) ** 2 / ((7 + 6 * nu) * (1 + m2) ** 2 + (20 + 12 * nu) * m2)

    def shear_areas(self) -> tuple:
        """(kAy, kAz): the shear areas along y and z (the shear stiffnesses kGAy, kGAz over G):
        k A for both but the I-section's and the channel's, whose web takes shear along y (hw tw)
        and their flanges along z ((5/6) 2 b tf)."""
        if self.shape in ("I-section", "channel"):
            d = self.dims
            return (d["h"] - 2 * d["tf"]) * d["tw"], 5.0 / 6.0 * 2 * d["b"] * d["tf"]
        if self.shape == "angle":   # each leg takes the shear along itself, (5/6) of its area
            d, a = self.dims, self.principal_angle
            leg_h, leg_b = 5.0 / 6.0 * d["h"] * d["t"], 5.0 / 6.0 * (d["b"] - d["t"]) * d["t"]
            c, s = math.cos(a), math.sin(a)
            return leg_h * c * c + leg_b * s * s, leg_h * s * s + leg_b * c * c
        kA = self.shear_coefficient() * self.A
        return kA, kA

    def plbeam_estiff(self, shear: bool = False) -> tuple:
        """ESTIFF of PLBEAM/PLBEAMNL: (EA, EI) with I = Iz (bending in the plane); with ``shear``
        (EA, EI, kGA): the shear-flexible (Timoshenko) beam, for short and deep beams."""
        m = self._mat()
        values = (m.E * self.A, m.E * self.Iz)
        return values + (m.G * self.shear_areas()[0],) if shear else values

    def beam_estiff(self, shear: bool = False, warping: bool = False) -> tuple:
        """ESTIFF of BEAM/BEAMNL: (EA, GIp, EIy, EIz), the torsional stiffness being G J (the
        catalogue's "GIp"; J = Ip only for round sections); with ``shear`` also (kGAy, kGAz);
        with ``warping`` (BEAMW) the seventh value EIw (the shear values 0 without ``shear``)."""
        m = self._mat()
        values = (m.E * self.A, m.G * self.J, m.E * self.Iy, m.E * self.Iz)
        if shear or warping:
            kGAy, kGAz = (m.G * a for a in self.shear_areas()) if shear else (0.0, 0.0)
            values += (kGAy, kGAz)
        return values + (m.E * self.Iw,) if warping else values

    def emass(self, rotary: bool = False, warping: bool = False) -> tuple:
        """EMASS: (ρA,), or for BEAM with ``rotary=True`` (ρA, ρIp, ρIy, ρIz), the rotary inertia
        of the cross-section per unit length (an extension of the manual's EMASS); with
        ``warping`` (BEAMW) also ρIw, the warping inertia."""
        rho = self._mat().rho
        if warping:
            rotational = (rho * self.Ip, rho * self.Iy, rho * self.Iz) if rotary else (0.0, 0.0, 0.0)
            return (rho * self.A, *rotational, rho * self.Iw)
        if rotary:
            return (rho * self.A, rho * self.Ip, rho * self.Iy, rho * self.Iz)
        return (rho * self.A,)

    def apply(self, model, *elements, rotary: bool = True, shear: bool = False):
        """Give the elements (numbers; none: every beam and truss of the model) the ESTIFF of
        this section and, if the material has a density, its EMASS: a spatial BEAM's with the
        rotary inertia of the section (ρIp, ρIy, ρIz; since issue 39 the default, without which
        the torsion of a leaf has no inertia and a 3-D leaf guide's modes fail), ``rotary=False``
        for ρA alone as the manual's EMASS; ``shear``: the beams' shear stiffness too
        (Timoshenko); a BEAMW also its warping stiffness EIw and inertia ρIw. Returns ``model``."""
        table = model.elements
        if not elements:
            elements = [e for e, el in table.items() if el.type_name in _ESTIFF]
        for e in elements:
            if e not in table:
                raise InputError(f"element {show(e)} is not defined")
            kind = table[e].type_name
            if kind not in _ESTIFF:
                raise InputError(f"a cross-section gives the data of beams and trusses, not of element {e} ({kind})")
            estiff = getattr(self, _ESTIFF[kind])
            options = {"shear": True} if shear and kind not in ("PLTRUSS", "TRUSS") else {}
            if kind == "BEAMW":  # its warping stiffness and inertia
                options["warping"] = True
            model.estiff(e, *estiff(**options))
            if self._mat().rho > 0.0:
                model.emass(e, *self.emass(rotary and kind in SPATIAL_BEAMS, warping=kind == "BEAMW"))
        return model

    # --- stresses ----------------------------------------------------------------------------

    def normal_stress(self, N, My, Mz):
        """Largest |normal stress| over the section under the axial force N and the bending
        moments My, Mz (arrays broadcast): |N|/A + hypot(My, Mz)/W for round sections, |N|/A +
        |My|/Wy + |Mz|/Wz (a corner) for the rectangle; for an angle the largest over its corners
        of |N|/A + |My| |z'|/Iy + |Mz| |y'|/Iz (principal coordinates; an upper bound where the
        moments' signs would make them cancel there)."""
        N, My, Mz = (np.abs(np.asarray(v, dtype=float)) for v in (N, My, Mz))
        if self._round:
            return N / self.A + np.hypot(My, Mz) / self.Wz
        if self.shape == "angle":   # the largest at one corner, not the two moduli's corners summed
            return N / self.A + np.max([My * abs(z) / self.Iy + Mz * abs(y) / self.Iz for y, z in self.corners],
                                       axis=0)
        return N / self.A + My / self.Wy + Mz / self.Wz

    def shear_stress(self, T, Vy, Vz):
        """Largest shear stress under the twisting moment T and the shear forces Vy, Vz:
        |T|/Wt + k hypot(Vy, Vz)/A (elementary theory; the sum of torsional and transverse
        shear is exact where both peak together, e.g. the surface of a round section on the
        neutral axis, and an upper bound otherwise)."""
        T, Vy, Vz = (np.abs(np.asarray(v, dtype=float)) for v in (T, Vy, Vz))
        if self.shape in ("I-section", "channel"):  # Vy in the web, Vz in the flanges (3/2 of the mean)
            d = self.dims
            return T / self.Wt + np.maximum(Vy / ((d["h"] - 2 * d["tf"]) * d["tw"]), 1.5 * Vz / (2 * d["b"] * d["tf"]))
        return T / self.Wt + self.shear_factor * np.hypot(Vy, Vz) / self.A

    @property
    def omega(self) -> float:
        """The largest sectorial coordinate (warping normal stress = bimoment · omega / Iw): b h/4
        for the rectangle, b (h − tf)/4 at the flange tips of the I-section, for the channel
        (h'/2) max(e, b' − e) at a flange's corner or tip (about the shear centre, e from the
        web), 0 for round ones."""
        d = self.dims
        if self.shape == "channel":
            e, bc = self.shear_centre, d["b"] - d["tw"] / 2
            return (d["h"] - d["tf"]) / 2 * max(e, bc - e)
        return {"rectangle": lambda: d["b"] * d["h"] / 4, "I-section": lambda: d["b"] * (d["h"] - d["tf"]) / 4}.get(
            self.shape, lambda: 0.0)()

    def principal_y(self, axis, y) -> tuple:
        """The direction of the section's principal y-axis for a beam along ``axis`` whose
        section's own y-axis (an angle's leg h; for the other sections their y, which is
        principal) points along ``y``: ``y`` made normal to the axis and turned about it by
        ``principal_angle`` (from y towards z). For a beam's definition line (``Model.beam(...,
        *sec.principal_y(axis, y))``) or the flexure builder's ``y=``."""
        x = np.asarray(axis, dtype=float)
        y = np.asarray(y, dtype=float)
        if x.shape != (3,) or y.shape != (3,) or not (np.isfinite(x).all() and np.isfinite(y).all()):
            raise InputError(f"principal_y: axis and y must be 3 finite numbers each, got {show(axis)}, {show(y)}")
        length = np.linalg.norm(x)
        if not length > 0:
            raise InputError("principal_y: the beam's axis has no length")
        x = x / length
        y = y - (y @ x) * x
        if not np.linalg.norm(y) > 1e-12 * length:
            raise InputError("principal_y: y lies along the beam's axis")
        y = y / np.linalg.norm(y)
        z = np.cross(x, y)
        a = self.principal_angle
        return tuple(float(v) for v in math.cos(a) * y + math.sin(a) * z)

    def __repr__(self):
        dims = ", ".join(f"{k} = {v:g}" for k, v in self.dims.items())
        mat = f" of {self.material.name or 'material'}" if self.material is not None else ""
        return f"<spacar.section {self.shape}({dims}){mat}: A = {self.A:.6g}, Iy = {self.Iy:.6g}, Iz = {self.Iz:.6g}>"


def _beam_types() -> tuple:
    """The planar and the spatial beams of the element catalogue (family Beam; planar: XY nodes)."""
    from . import _core

    beams = [t for t in _core.element_catalogue() if t.family.name == "Beam"]
    return (frozenset(t.name for t in beams if t.nodes[0].name == "XY"),
            frozenset(t.name for t in beams if t.nodes[0].name == "XYZ"))


PLANAR_BEAMS, SPATIAL_BEAMS = _beam_types()
# The ESTIFF method of each element type a section describes.
_ESTIFF = {**dict.fromkeys(PLANAR_BEAMS, "plbeam_estiff"), **dict.fromkeys(SPATIAL_BEAMS, "beam_estiff"),
           "PLTRUSS": "truss_estiff", "TRUSS": "truss_estiff"}


def _rectangle_torsion(a: float, c: float) -> tuple:
    """Saint-Venant torsion of an a × c rectangle, a ≥ c: (J, Wt) from the series of the
    Prandtl stress function (Timoshenko & Goodier §109), summed over odd n until converged:
    J = (a c³/3) [1 − (192 c / π⁵ a) Σ tanh(nπa/2c)/n⁵], τmax = Gθ c [1 − (8/π²) Σ 1/(n² cosh(nπa/2c))]
    at the middle of the long sides, so Wt = J / (c [...])."""
    s_j = s_t = 0.0
    for n in range(1, 2001, 2):
        s_j += math.tanh(n * math.pi * a / (2 * c)) / n**5
        arg = n * math.pi * a / (2 * c)
        s_t += 0.0 if arg > 700 else 1.0 / (n * n * math.cosh(arg))
    J = a * c**3 / 3.0 * (1.0 - 192.0 * c / (math.pi**5 * a) * s_j)
    tau = c * (1.0 - 8.0 / math.pi**2 * s_t)
    return J, J / tau


def rectangle(b, h, material: Material | None = None) -> Section:
    """A solid b × h rectangle: ``h`` along y (PLBEAM: the height in the plane of bending, e.g.
    the thickness of a leaf spring), ``b`` along z (PLBEAM: the width out of the plane).

    A = bh, Iz = b h³/12, Iy = h b³/12, Wz = b h²/6, Wy = h b²/6; J and Wt by the Saint-Venant
    series (square: J = 0.1406 h⁴, Wt = 0.2082 h³; thin, b ≫ h: J → b h³/3); shear factor 3/2."""
    b, h = _positive(b, "b"), _positive(h, "h")
    J, Wt = _rectangle_torsion(max(b, h), min(b, h))
    return Section("rectangle", {"b": b, "h": h}, material, A=b * h, Iy=h * b**3 / 12, Iz=b * h**3 / 12, J=J,
                   Wy=h * b**2 / 6, Wz=b * h**2 / 6, Wt=Wt, shear_factor=1.5, round_=False, Iw=b**3 * h**3 / 144)


def circle(d, material: Material | None = None) -> Section:
    """A solid circle of diameter ``d``: A = πd²/4, I = πd⁴/64, J = Ip = πd⁴/32, W = πd³/32,
    Wt = πd³/16; shear factor 4/3."""
    d = _positive(d, "d")
    I = math.pi * d**4 / 64
    return Section("circle", {"d": d}, material, A=math.pi * d**2 / 4, Iy=I, Iz=I, J=2 * I, Wy=I / (d / 2),
                   Wz=I / (d / 2), Wt=2 * I / (d / 2), shear_factor=4.0 / 3.0, round_=True)


def tube(d, t, material: Material | None = None) -> Section:
    """A round tube of outer diameter ``d`` and wall thickness ``t`` (t ≤ d/2; d/2: the solid
    circle): with the inner diameter di = d − 2t, A = π(d² − di²)/4, I = π(d⁴ − di⁴)/64,
    J = Ip = 2I, W = 2I/d, Wt = 4I/d; shear factor (4/3)(r² + r ri + ri²)/(r² + ri²) (4/3 for the
    solid circle, → 2 for a thin wall)."""
    d, t = _positive(d, "d"), _positive(t, "t")
    if t > d / 2:
        raise InputError(f"the wall thickness t = {t:g} of a tube exceeds its outer radius d/2 = {d / 2:g}")
    di = d - 2 * t
    I = math.pi * (d**4 - di**4) / 64
    r, ri = d / 2, di / 2
    k = 4.0 / 3.0 * (r * r + r * ri + ri * ri) / (r * r + ri * ri)
    return Section("tube", {"d": d, "t": t}, material, A=math.pi * (d**2 - di**2) / 4, Iy=I, Iz=I, J=2 * I,
                   Wy=2 * I / d, Wz=2 * I / d, Wt=4 * I / d, shear_factor=k, round_=True)


def i_beam(h, b, tw, tf, material: Material | None = None) -> Section:
    """A thin-walled, doubly symmetric I-section (fillets left out): depth ``h`` along y (the web),
    flange width ``b`` along z, web thickness ``tw``, flange thickness ``tf``. With the web's
    height hw = h − 2tf: A = 2 b tf + hw tw; Iz = (b h³ − (b − tw) hw³)/12 (the strong axis:
    bending in the web's plane), Iy = (2 tf b³ + hw tw³)/12; the open section's torsion
    J = (2 b tf³ + hw tw³)/3 and Wt = J / max(tf, tw); the warping constant
    Iw = tf b³ (h − tf)²/24 (BEAMW's EIw: the tables' value for rolled profiles); the shear
    carried by the web, shear factor A/(hw tw) (and Timoshenko's k = hw tw / A)."""
    h, b, tw, tf = (_positive(v, name) for v, name in ((h, "h"), (b, "b"), (tw, "tw"), (tf, "tf")))
    hw = h - 2 * tf
    if not hw > 0 or tw > b:
        raise InputError(f"an I-section needs h > 2 tf and tw ≤ b, got h = {h:g}, b = {b:g}, tw = {tw:g}, tf = {tf:g}")
    A = 2 * b * tf + hw * tw
    Iz = (b * h**3 - (b - tw) * hw**3) / 12
    Iy = (2 * tf * b**3 + hw * tw**3) / 12
    J = (2 * b * tf**3 + hw * tw**3) / 3
    return Section("I-section", {"h": h, "b": b, "tw": tw, "tf": tf}, material, A=A, Iy=Iy, Iz=Iz, J=J,
                   Wy=Iy / (b / 2), Wz=Iz / (h / 2), Wt=J / max(tf, tw), shear_factor=A / (hw * tw), round_=False,
                   Iw=tf * b**3 * (h - tf) ** 2 / 24)


def channel(h, b, tw, tf, material: Material | None = None) -> Section:
    """A thin-walled channel (C- or U-section, fillets left out): depth ``h`` along y (the web),
    flange width ``b`` along z from the web's outer face, web thickness ``tw``, flange
    thickness ``tf``; symmetric about z. With hw = h − 2tf: A = 2 b tf + hw tw,
    Iz = (b h³ − (b − tw) hw³)/12 (the strong axis), Iy about the centroid's axis along the web
    (the centroid z̄ = (b² tf + hw tw²/2)/A from the web's face), J = (2 b tf³ + hw tw³)/3; on the
    centre lines (flanges h' = h − tf apart, b' = b − tw/2 from the web's) the warping constant
    about the shear centre Iw = tf b'³ h'² (3 b' tf + 2 h' tw) / (12 (6 b' tf + h' tw)) and the
    shear centre e = 3 b'² tf / (6 b' tf + h' tw) from the web's centre line, on the side away
    from the flanges (``shear_centre``). spacar's beams put the shear centre on their axis: a
    load through the centroid of a channel would also twist it, which the beam leaves out."""
    h, b, tw, tf = (_positive(v, name) for v, name in ((h, "h"), (b, "b"), (tw, "tw"), (tf, "tf")))
    hw = h - 2 * tf
    if not hw > 0 or tw >= b:
        raise InputError(f"a channel needs h > 2 tf and tw < b, got h = {h:g}, b = {b:g}, tw = {tw:g}, tf = {tf:g}")
    A = 2 * b * tf + hw * tw
    zc = (b * b * tf + hw * tw * tw / 2) / A
    Iz = (b * h**3 - (b - tw) * hw**3) / 12
    Iy = 2 * (tf * b**3 / 12 + b * tf * (b / 2 - zc) ** 2) + hw * tw**3 / 12 + hw * tw * (tw / 2 - zc) ** 2
    J = (2 * b * tf**3 + hw * tw**3) / 3
    hc, bc = h - tf, b - tw / 2
    Iw = tf * bc**3 * hc**2 * (3 * bc * tf + 2 * hc * tw) / (12 * (6 * bc * tf + hc * tw))
    section = Section("channel", {"h": h, "b": b, "tw": tw, "tf": tf}, material, A=A, Iy=Iy, Iz=Iz, J=J,
                      Wy=Iy / max(zc, b - zc), Wz=Iz / (h / 2), Wt=J / max(tf, tw), shear_factor=A / (hw * tw),
                      round_=False, Iw=Iw)
    section.shear_centre = 3 * bc**2 * tf / (6 * bc * tf + hc * tw)
    return section


def angle(h, b, t, material: Material | None = None) -> Section:
    """An angle (L-section, fillets and toe roundings left out): a leg of length ``h`` along y and
    one of length ``b`` along z from the outer corner, both ``t`` thick. Its principal axes are
    inclined to the legs: ``Iy``, ``Iz`` are the principal second moments (Iz the larger, about
    the principal z-axis), ``principal_angle`` α turns the legs' y-axis to the principal y-axis
    (about the beam's axis, from y towards z; tan 2α = 2 Iyz/(Izz − Iyy) of the moments about the
    centroid in the legs' axes), and :meth:`Section.principal_y` gives the direction of the
    principal y-axis for a beam's definition line. ``centroid`` (ȳ, z̄) and ``shear_centre``
    (the legs' centre lines' crossing, (t/2, t/2)) from the outer corner; spacar's beams keep the
    shear centre on their axis, so a load through the centroid does not twist the angle as it
    would. A = t (h + b − t); J = (h + b − t) t³/3; the warping constant of thin legs meeting at
    the shear centre, (t³/36)(h'³ + b'³) with h' = h − t/2, b' = b − t/2 (secondary warping
    only); the section moduli from the corners' distances to the principal axes (``corners``:
    (y', z') of the six); each leg takes the shear along its length ((5/6) of its area, projected
    on the principal axes, the coupling between the two shear directions left out)."""
    h, b, t = (_positive(v, name) for v, name in ((h, "h"), (b, "b"), (t, "t")))
    if not (t < h and t < b):
        raise InputError(f"an angle needs t < h and t < b, got h = {h:g}, b = {b:g}, t = {t:g}")
    # The legs as two rectangles [y0, y1] × [z0, z1] from the outer corner: their area moments.
    legs = ((0.0, h, 0.0, t), (0.0, t, t, b))
    A = sum((y1 - y0) * (z1 - z0) for y0, y1, z0, z1 in legs)
    yc = sum((y1**2 - y0**2) / 2 * (z1 - z0) for y0, y1, z0, z1 in legs) / A
    zc = sum((y1 - y0) * (z1**2 - z0**2) / 2 for y0, y1, z0, z1 in legs) / A
    Syy = sum((y1**3 - y0**3) / 3 * (z1 - z0) for y0, y1, z0, z1 in legs) - A * yc**2     # ∫ y² about the centroid
    Szz = sum((y1 - y0) * (z1**3 - z0**3) / 3 for y0, y1, z0, z1 in legs) - A * zc**2
    Syz = sum((y1**2 - y0**2) * (z1**2 - z0**2) / 4 for y0, y1, z0, z1 in legs) - A * yc * zc
    alpha = 0.5 * math.atan2(2 * Syz, Syy - Szz)      # the principal y': ∫ y'² the largest
    c, s = math.cos(alpha), math.sin(alpha)
    Iz = Syy * c * c + 2 * Syz * c * s + Szz * s * s     # ∫ y'² dA: bending about z'
    Iy = Syy * s * s - 2 * Syz * c * s + Szz * c * c     # ∫ z'² dA
    corners = np.array([(0, 0), (h, 0), (h, t), (t, t), (t, b), (0, b)], dtype=float) - (yc, zc)
    yp, zp = corners @ np.array([c, s]), corners @ np.array([-s, c])
    J = (h + b - t) * t**3 / 3
    hc, bc = h - t / 2, b - t / 2
    section = Section("angle", {"h": h, "b": b, "t": t}, material, A=A, Iy=Iy, Iz=Iz, J=J,
                      Wy=Iy / np.abs(zp).max(), Wz=Iz / np.abs(yp).max(), Wt=J / t,
                      shear_factor=1.5 * A / (t * min(h, b)),  # the largest shear: 3/2 of the mean in the shorter leg
                      round_=False, Iw=t**3 * (hc**3 + bc**3) / 36)
    section.principal_angle = alpha
    section.corners = tuple(zip(yp.tolist(), zp.tolist()))   # (y', z') in the principal axes
    section.centroid = (yc, zc)
    section.shear_centre = (t / 2, t / 2)
    return section


# ------------------------------------------------------------------------------------------------
# Stresses of a solution
# ------------------------------------------------------------------------------------------------

class Stresses:
    """The largest stresses per element at each output (:func:`stresses`): ``t`` (nt), ``elements``
    (the element numbers of the columns), ``normal`` and ``shear`` (nt × n_elements), and the
    section forces they come from in ``forces[e]`` (a dict of arrays N, T, My, Mz at both ends
    as (nt × 2), Vy, Vz)."""

    def __init__(self, t, elements, normal, shear, forces):
        self.t, self.elements, self.normal, self.shear, self.forces = t, elements, normal, shear, forces

    def element(self, e: int):
        """(normal, shear) of element e over the outputs."""
        if e not in self.elements:
            raise InputError(f"element {show(e)} has no stresses here (elements: {self.elements})")
        k = self.elements.index(e)
        return self.normal[:, k], self.shear[:, k]

    def max(self) -> dict:
        """The largest normal and shear stress over all outputs and elements, with where:
        ``{"normal": (value, element, output index), "shear": (...)}``."""
        out = {}
        for name in ("normal", "shear"):
            a = getattr(self, name)
            if a.size == 0:
                out[name] = (0.0, None, None)
                continue
            i, k = np.unravel_index(np.argmax(a), a.shape)
            out[name] = (float(a[i, k]), self.elements[k], int(i))
        return out

    KINDS = ("normal", "shear", "von_mises")

    def at(self, k: int, kind: str = "normal") -> dict:
        """``{element: stress}`` at output index ``k``: the largest ``"normal"`` or ``"shear"``
        stress of each element, or ``"von_mises"``, √(σ² + 3τ²) of the two (an upper bound of
        the equivalent stress: the largest σ and τ need not occur at the same point)."""
        if kind not in self.KINDS:
            raise InputError(f"kind must be one of {', '.join(self.KINDS)}, got {show(kind)}")
        k = range(len(self.t))[k]
        values = {"normal": self.normal[k], "shear": self.shear[k],
                  "von_mises": np.sqrt(self.normal[k] ** 2 + 3.0 * self.shear[k] ** 2)}[kind]
        return dict(zip(self.elements, (float(v) for v in values)))

    def __repr__(self):
        return f"<spacar.section.Stresses: {len(self.t)} outputs x {len(self.elements)} elements>"


def section_forces(results, e: int, type_name: str, l0: float) -> dict:
    """The section forces of element e from its generalized stresses σ (formulation §4.2, §4.8):
    axial force N = σ1; end moments M = l0 σ of the bending pairs (σ conjugate to the bending
    deformations l0 sin θ: M = l0 σ cos θ, the element's end rotations θ relative to its chord
    being small); shear force V = σp − σq of each pair ((Mp + Mq)/l0 in the beam's sign: zero
    for constant curvature); twisting moment T = l0 σ2 (BEAM; BEAMW: l0 (σ2 − σ7 + σ8), the
    warping torque included, and ``warping``, the twist's second derivative ψ'' at both ends,
    whose bimoment EIw ψ'' gives the warping normal stress E ω ψ'')."""
    s = lambda i: results.sigma[:, results.deformation_index(e, i)]  # noqa: E731
    zero = np.zeros(len(results.t))
    if type_name in ("PLTRUSS", "TRUSS"):
        ends = np.zeros((len(zero), 2))
        return {"N": s(1), "T": zero, "My": ends, "Mz": ends, "Vy": zero, "Vz": zero}
    if type_name in PLANAR_BEAMS:
        return {"N": s(1), "T": zero, "My": np.zeros((len(zero), 2)), "Mz": l0 * np.column_stack([s(2), s(3)]),
                "Vy": s(2) - s(3), "Vz": zero}
    out = {"N": s(1), "T": l0 * s(2), "My": l0 * np.column_stack([s(3), s(4)]),
           "Mz": l0 * np.column_stack([s(5), s(6)]), "Vz": s(3) - s(4), "Vy": s(5) - s(6)}
    if type_name == "BEAMW":  # Saint-Venant's and the warping torque; the warping deformations
        out["T"] = l0 * (s(2) - s(7) + s(8))
        d = lambda i: results.e[:, results.deformation_index(e, i)]  # noqa: E731
        out["warping"] = np.column_stack([4 * d(7) - 2 * d(8), 4 * d(8) - 2 * d(7)]) / l0**3  # ψ'' at the ends
    return out


def stresses(results, sections) -> Stresses:
    """The largest normal stress (|N|/A plus bending, the larger of both ends, both bending axes
    of BEAM: :meth:`Section.normal_stress`) and the largest shear stress (torsion plus transverse
    shear: :meth:`Section.shear_stress`) of beams and trusses at every output of ``results``.

    ``sections``: one :class:`Section` for every beam and truss of the model, or a dict
    ``{element: Section}`` for those elements only. The stresses σ must be complete: those of a
    static analysis are; a simulation fills the reaction stresses of rigid deformations (e.g. an
    axially rigid beam's N) only with ``FORCEMODE 2``."""
    geometry = results.geometry
    if geometry is None:
        raise InputError("these results have no geometry (element types and lengths) to compute stresses with")
    table = {el.id: el for el in geometry.elements}
    if isinstance(sections, Section):
        sections = {e: sections for e, el in table.items() if el.type in _ESTIFF}
    elif not isinstance(sections, dict):
        raise InputError(f"sections must be a Section or a dict {{element: Section}}, got {show(sections)}")
    elements = sorted(sections)
    nt = len(results.t)
    normal, shear, forces = np.zeros((nt, len(elements))), np.zeros((nt, len(elements))), {}
    for k, e in enumerate(elements):
        sec = sections[e]
        if not isinstance(sec, Section):
            raise InputError(f"the section of element {e} must be a spacar.section.Section, got {show(sec)}")
        if e not in table or table[e].type not in _ESTIFF:
            kind = f" ({table[e].type})" if e in table else ""
            raise InputError(f"element {show(e)}{kind} is not a beam or truss of these results")
        el = table[e]
        f = section_forces(results, e, el.type, el.l0)
        forces[e] = f
        warping = np.abs(f["warping"]) * sec._mat().E * sec.omega if "warping" in f else np.zeros((nt, 2))
        normal[:, k] = np.maximum(sec.normal_stress(f["N"], f["My"][:, 0], f["Mz"][:, 0]) + warping[:, 0],
                                  sec.normal_stress(f["N"], f["My"][:, 1], f["Mz"][:, 1]) + warping[:, 1])
        shear[:, k] = sec.shear_stress(f["T"], f["Vy"], f["Vz"])
    return Stresses(np.asarray(results.t), elements, normal, shear, forces)
