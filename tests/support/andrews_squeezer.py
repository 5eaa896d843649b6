"""Andrews' squeezing mechanism (the "seven-body mechanism" of Hairer & Wanner, *Solving Ordinary
Differential Equations II*, §VII.7, and of the Test Set for IVP Solvers, problem "andrews"):
seven rigid bodies, six closing constraints, one degree of freedom, driven by a constant torque
on the crank and loaded by a spring; 0 ≤ t ≤ 0.03 s from rest.

Two descriptions of the same mechanism:

* `squeezer_model()`: a spacar model built from the geometry of the test set — rigid `PLBEAM`s
  from a pivot of each body to its other points (joints, centre of mass, spring attachment),
  `MASS` at the centres of mass and on the bodies' orientation nodes, pins by shared position
  nodes, `PLHINGE`s for the crank's drive (the degree of freedom) and for the three relative
  angles of the test set, and a `PLTRUSS` for the spring.
* `reference_solution()`: the test set's own equations of motion in its seven angles
  (mass matrix, forces, constraints), an index-3 DAE, solved here in its index-1 form —
  accelerations and multipliers from [M Gᵀ; G 0] at every call — with SciPy's DOP853.

The angles are those of the test set: β (crank), Θ (coupler relative to the crank), γ (body 3),
Φ (body 4 relative to body 5), δ (body 5), Ω (body 6 relative to body 7), ε (body 7).
"""
from __future__ import annotations

import numpy as np

import spacar

# Data of the test set (SI units).
M = (0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498)
I = (2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5)
XA, YA = -0.06934, -0.00227
XB, YB = -0.03635, 0.03273
XC, YC = 0.014, 0.072
D, DA, E, EA = 28e-3, 115e-4, 2e-2, 1421e-5
RR, RA = 7e-3, 92e-5
SS, SA, SB, SC, SD = 35e-3, 1874e-5, 1043e-5, 18e-3, 2e-2
TA, TB = 2308e-5, 916e-5
U, UA, UB = 4e-2, 1228e-5, 449e-5
ZF, ZT, FA = 2e-2, 4e-2, 1421e-5
MOM = 0.033          # driving torque on the crank [N m]
C0 = 4530.0          # spring stiffness [N/m]
L0 = 0.07785         # spring natural length [m]
T_END = 0.03

# Consistent initial angles (β, Θ, γ, Φ, δ, Ω, ε), at rest.
Q0 = np.array([-0.0617138900142764496358948458001, 0.0,
               0.455279819163070380255912382449, 0.222668390165885884674473185609,
               0.487364979543842550225598953530, -0.222668390165885884674473185609,
               1.23054744454982119249735015568])

# The test set's reference angles at t = 0.03 (computed there with PSIDE at rtol = atol = 1e-14:
# Mazzia & Magherini, Test Set for IVP Solvers, release 2.4, problem "andrews").
Q_END_PUBLISHED = np.array([0.1581077119629904e2, -0.1575637105984298e2, 0.4082224013073101e-1,
                            -0.5347301163226948, 0.5244099658805304, 0.5347301163226948,
                            0.1048080741042263e1])

ANGLE_NAMES = ("beta", "theta", "gamma", "phi", "delta", "omega", "epsilon")


def _rot(a):
    return np.array([np.cos(a), np.sin(a)])


def points(q):
    """Positions of the joints, centres of mass and spring ends for the angles q, from the test
    set's constraint equations and mass matrix (the centre of mass of each body where its kinetic
    energy puts it; for the bodies turning about a fixed pivot only its distance matters)."""
    be, th, ga, ph, de, om, ep = q
    o = np.zeros(2)
    a = np.array([XA, YA])
    b = np.array([XB, YB])
    p = RR * _rot(be)
    e_joint = p - D * _rot(be + th)
    f = a + ZT * _rot(de)                       # body 4 on body 5
    g = a + U * np.array([np.sin(ep), -np.cos(ep)])   # body 6 on body 7
    sp = b + np.array([SD * np.cos(ga) + SC * np.sin(ga), SD * np.sin(ga) - SC * np.cos(ga)])
    return {
        "O": o, "P": p, "E": e_joint, "B": b, "D": sp, "C": np.array([XC, YC]), "A": a,
        "F": f, "G": g,
        "S1": RA * _rot(be),
        "S2": p - DA * _rot(be + th),
        "S3": b + np.array([SA * np.sin(ga) + SB * np.cos(ga), -SA * np.cos(ga) + SB * np.sin(ga)]),
        "S4": f + (E - EA) * np.array([np.sin(ph + de), -np.cos(ph + de)]),
        "S5": a + np.array([TA * np.cos(de) - TB * np.sin(de), TA * np.sin(de) + TB * np.cos(de)]),
        "S6": g + (ZF - FA) * _rot(om + ep),
        "S7": a + np.array([UA * np.sin(ep) + UB * np.cos(ep), -UA * np.cos(ep) + UB * np.sin(ep)]),
    }


# --- spacar model -----------------------------------------------------------------------------

_XY = {name: k for k, name in enumerate(
    ("O", "P", "E", "B", "D", "C", "A", "F", "G", "S1", "S2", "S3", "S4", "S5", "S6", "S7"), 1)}
BETA_GROUND = 20
BETA = {body: 20 + body for body in range(1, 8)}      # orientation node of body 1..7

# Each body: a pivot and the other points joined to it by rigid beams, which share the body's
# orientation node BETA[k] at the pivot (nodes 41, 42, ... at their far ends).
_BODIES = {
    1: ("O", ("P", "S1")),
    2: ("P", ("E", "S2")),
    3: ("B", ("E", "D", "S3")),
    4: ("F", ("E", "S4")),
    5: ("A", ("F", "S5")),
    6: ("G", ("E", "S6")),
    7: ("A", ("G", "S7")),
}
# Element numbers of the hinges and the spring.
DRIVE, HINGE_THETA, HINGE_PHI, HINGE_OMEGA, SPRING = 101, 102, 103, 104, 105


def squeezer_model(eps=1e-10, n_out=1):
    """The squeezer as a spacar model at its initial state, with TIMESTEP n_out over 0.03 s,
    EPSINT = EPSIND = eps and EPSKIN 1e-13 (kinematic iterations well below eps). Node `BETA[k]` carries body k's absolute rotation since t = 0;
    element DRIVE (crank against the ground, DYNE) is the degree of freedom, HINGE_THETA,
    HINGE_PHI, HINGE_OMEGA (released) measure the changes of Θ, Φ, Ω, and SPRING is the spring."""
    pts = points(Q0)
    m = spacar.Model()
    elem = 1
    for body, (pivot, others) in _BODIES.items():
        r = BETA[body]
        for other in others:
            # The far end's own orientation node: the beam is rigid, it turns with r.
            m.plbeam(elem, _XY[pivot], r, _XY[other], 40 + elem)
            elem += 1
        m.mass(_XY[f"S{body}"], M[body - 1])
        m.mass(r, I[body - 1])
    for name, k in _XY.items():
        m.x(k, *pts[name])
    m.plhinge(DRIVE, BETA_GROUND, BETA[1])
    m.plhinge(HINGE_THETA, BETA[1], BETA[2])
    m.plhinge(HINGE_PHI, BETA[5], BETA[4])
    m.plhinge(HINGE_OMEGA, BETA[7], BETA[6])
    m.pltruss(SPRING, _XY["D"], _XY["C"])
    m.lengtho(SPRING, L0)
    m.estiff(SPRING, C0 * L0)                  # σ = (EA/l0)·(l − l0): EA = c0·l0
    for k in ("O", "B", "C", "A"):
        m.fix(_XY[k])
    m.fix(BETA_GROUND)
    m.dyne(DRIVE, 1)
    m.rlse(HINGE_THETA)
    m.rlse(HINGE_PHI)
    m.rlse(HINGE_OMEGA)
    m.rlse(SPRING)
    m.force(BETA[1], MOM)
    m.timestep(n_out, T_END)
    m.apply("EPSKIN", 1e-13)
    m.apply("EPSINT", eps)
    m.apply("EPSIND", eps)
    return m


def _relative(rot):
    return np.array([rot[1], rot[2] - rot[1], rot[3], rot[4] - rot[5], rot[5],
                     rot[6] - rot[7], rot[7]])


def angles(res):
    """The test set's seven angles at the output times of a spacar run of `squeezer_model()`,
    shape (nt, 7), from the absolute rotations of the bodies' orientation nodes."""
    rot = {body: res.coordinate(BETA[body], 1) for body in BETA}
    return Q0 + _relative(rot).T


def rates(res):
    """Their rates, shape (nt, 7)."""
    rot = {body: res.coordinate(BETA[body], 1, "XD") for body in BETA}
    return _relative(rot).T


# --- the test set's equations of motion ---------------------------------------------------------

def mass_matrix(q):
    _, th, _, ph, _, om, _ = q
    m1, m2, m3, m4, m5, m6, m7 = M
    i1, i2, i3, i4, i5, i6, i7 = I
    mm = np.zeros((7, 7))
    mm[0, 0] = m1 * RA**2 + m2 * (RR**2 - 2 * DA * RR * np.cos(th) + DA**2) + i1 + i2
    mm[1, 0] = mm[0, 1] = m2 * (DA**2 - DA * RR * np.cos(th)) + i2
    mm[1, 1] = m2 * DA**2 + i2
    mm[2, 2] = m3 * (SA**2 + SB**2) + i3
    mm[3, 3] = m4 * (E - EA)**2 + i4
    mm[4, 3] = mm[3, 4] = m4 * ((E - EA)**2 + ZT * (E - EA) * np.sin(ph)) + i4
    mm[4, 4] = (m4 * (ZT**2 + 2 * ZT * (E - EA) * np.sin(ph) + (E - EA)**2)
                + m5 * (TA**2 + TB**2) + i4 + i5)
    mm[5, 5] = m6 * (ZF - FA)**2 + i6
    mm[6, 5] = mm[5, 6] = m6 * ((ZF - FA)**2 - U * (ZF - FA) * np.sin(om)) + i6
    mm[6, 6] = (m6 * ((ZF - FA)**2 - 2 * U * (ZF - FA) * np.sin(om) + U**2)
                + m7 * (UA**2 + UB**2) + i6 + i7)
    return mm


def forces(q, qd):
    """The test set's generalized forces: drive torque, spring, and the velocity terms."""
    be, th, ga, ph, de, om, ep = q
    bep, thp, _, php, dep, omp, epp = qd
    m2, m4, m6 = M[1], M[3], M[5]
    xd = SD * np.cos(ga) + SC * np.sin(ga) + XB
    yd = SD * np.sin(ga) - SC * np.cos(ga) + YB
    lang = np.hypot(xd - XC, yd - YC)
    force = -C0 * (lang - L0) / lang
    fx, fy = force * (xd - XC), force * (yd - YC)
    return np.array([
        MOM - m2 * DA * RR * thp * (thp + 2 * bep) * np.sin(th),
        m2 * DA * RR * bep**2 * np.sin(th),
        fx * (SC * np.cos(ga) - SD * np.sin(ga)) + fy * (SD * np.cos(ga) + SC * np.sin(ga)),
        m4 * ZT * (E - EA) * dep**2 * np.cos(ph),
        -m4 * ZT * (E - EA) * php * (php + 2 * dep) * np.cos(ph),
        -m6 * U * (ZF - FA) * epp**2 * np.cos(om),
        m6 * U * (ZF - FA) * omp * (omp + 2 * epp) * np.cos(om),
    ])


# The six constraints g(q) = 0 of the test set, each a sum of terms c·cos(a·q) or c·sin(a·q) with
# a an integer vector over the angles, plus a constant; G = ∂g/∂q and the velocity term
# (∂(G q̇)/∂q) q̇ follow from the terms.
def _terms():
    def a(*idx):
        v = np.zeros(7)
        v[list(idx)] = 1.0
        return v
    be, th, ga, ph, de, om, ep = range(7)
    ex = [(RR, "cos", a(be)), (-D, "cos", a(be, th))]        # x of joint E from the crank side
    ey = [(RR, "sin", a(be)), (-D, "sin", a(be, th))]
    return [
        (ex + [(-SS, "sin", a(ga))], -XB),
        (ey + [(SS, "cos", a(ga))], -YB),
        (ex + [(-E, "sin", a(ph, de)), (-ZT, "cos", a(de))], -XA),
        (ey + [(E, "cos", a(ph, de)), (-ZT, "sin", a(de))], -YA),
        (ex + [(-ZF, "cos", a(om, ep)), (-U, "sin", a(ep))], -XA),
        (ey + [(-ZF, "sin", a(om, ep)), (U, "cos", a(ep))], -YA),
    ]


_G_TERMS = _terms()


def constraints(q, qd):
    """g(q), G(q) = ∂g/∂q and the velocity term γ = d/dt(G) q̇ (so that g̈ = G q̈ + γ)."""
    g = np.zeros(6)
    jac = np.zeros((6, 7))
    gam = np.zeros(6)
    for i, (terms, const) in enumerate(_G_TERMS):
        g[i] = const
        for c, fn, a in terms:
            phi, phid = a @ q, a @ qd
            if fn == "cos":
                g[i] += c * np.cos(phi)
                jac[i] -= c * np.sin(phi) * a
                gam[i] -= c * np.cos(phi) * phid**2
            else:
                g[i] += c * np.sin(phi)
                jac[i] += c * np.cos(phi) * a
                gam[i] -= c * np.sin(phi) * phid**2
    return g, jac, gam


def _rhs(_t, y):
    q, qd = y[:7], y[7:]
    _, jac, gam = constraints(q, qd)
    kkt = np.zeros((13, 13))
    kkt[:7, :7] = mass_matrix(q)
    kkt[:7, 7:] = jac.T
    kkt[7:, :7] = jac
    sol = np.linalg.solve(kkt, np.concatenate([forces(q, qd), -gam]))
    return np.concatenate([qd, sol[:7]])


def reference_solution(t_eval=(T_END,), rtol=1e-12, atol=1e-13):
    """The angles and their rates (7 + 7) at the times t_eval from the test set's equations in
    index-1 form, integrated by SciPy's DOP853; returns (y of shape (len(t_eval), 14), the largest
    position-constraint residual |g| at those times)."""
    from scipy.integrate import solve_ivp

    sol = solve_ivp(_rhs, (0.0, T_END), np.concatenate([Q0, np.zeros(7)]), method="DOP853",
                    t_eval=np.asarray(t_eval, float), rtol=rtol, atol=atol)
    assert sol.success, sol.message
    y = sol.y.T
    drift = max(np.abs(constraints(row[:7], row[7:])[0]).max() for row in y)
    return y, drift
