"""Model reduction of a large flexure model (issue 40): a cantilever of 400 PLBEAMs (1200 DOFs,
2400 states) in its lowest modes (state_space(modes=k), the sparse eigensolver) keeps its static
gain exactly (L³/3EI) and, across the band of its first five modes, its tip receptance within
1e-8 of the static compliance of the full model's response (each frequency solved directly on the
nodal saddle-point system, not by modes); balanced truncation of the damped modal model stays
within its H∞ error bound, the error's H∞ norm computed by python-control."""
from __future__ import annotations

import numpy as np
import pytest

import spacar
from support.planar_models import tip_loaded_beam

N, L, EI = 400, 1.2, 2.0
STATIC = L**3 / (3 * EI)


@pytest.fixture(scope="module")
def beam():
    return tip_loaded_beam(N, L=L, EI=EI)


def full_receptance(lin, freqs):
    """The tip's y per unit tip force of the whole model, (K − ω² M) x = F solved on the nodal
    matrices at each frequency (the sparse saddle-point system with its refinement)."""
    nodal, sim = lin.nodal, lin._sim
    tip = nodal.coordinate_labels.index((2 * N + 1, 2))
    free = list(nodal.free)
    load = np.zeros(len(free))
    load[free.index(tip)] = 1.0
    out = []
    for f in freqs:
        sim.nodal_factorize(1.0, 1.0, -(2 * np.pi * f) ** 2, 0.0)
        out.append(sim.nodal_solve(load)[free.index(tip)])
    return np.array(out)


def test_modal_truncation_keeps_the_static_gain_and_the_band_of_the_first_modes(beam):
    lin = spacar.linearize(beam)
    f = lin.eigenfrequencies(k=5)
    edges = np.concatenate([[0.0], f])
    band = np.concatenate([np.linspace(a, b, 9)[1:-1] for a, b in zip(edges[:-1], edges[1:])])
    full = full_receptance(lin, band)
    assert full_receptance(lin, [0.0])[0] == pytest.approx(STATIC, rel=1e-12)
    for k, tolerance in ((20, 1e-7), (30, 1e-8)):
        ss = spacar.state_space(beam, modes=k)
        assert ss.A.shape == (2 * k, 2 * k)
        assert ss.static_gain()[0, 0] == pytest.approx(STATIC, rel=1e-12)
        reduced = ss.frequency_response(band)[:, 0, 0]
        assert np.abs(reduced - full).max() < tolerance * STATIC


def test_balanced_truncation_stays_within_its_bound(beam):
    control = pytest.importorskip("control")
    ss = spacar.state_space(beam, modes=30, damping=0.01)
    for k in (6, 12):
        red = ss.reduce(k, method="balanced")
        error = control.ss(ss.A, ss.B, ss.C, ss.D) - control.ss(red.A, red.B, red.C, red.D)
        tip = control.ss(error.A, error.B, error.C[:1], error.D[:1])   # the tip's position
        assert control.norm(tip, p="inf") <= red.error_bound
