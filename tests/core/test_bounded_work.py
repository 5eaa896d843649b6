"""Large singular models end in a SpacarError that names the cause, at once (issue 24, finding 1).

Before, a chain of 20 000 massless PLBEAMs spent minutes (quadratic in the chain's length: the
labels of its degrees of freedom) and then blamed the memory limit of a dense diagnosis."""
import time

import pytest

import spacar
from spacar import SingularMassError


def beam_chain(n, mass_at=()):
    """n PLBEAMs along x from the clamped nodes 1, 2, every deformation DYNE; EMASS only on the
    elements in mass_at."""
    m = spacar.Model()
    for k in range(1, n + 1):
        m.plbeam(k, 2 * k - 1, 2 * k, 2 * k + 1, 2 * k + 2)
        m.x(2 * k + 1, k / n, 0.0)
        m.estiff(k, 1.0, 1.0)
        m.dyne(k, 1, 2, 3)
        if k in mass_at:
            m.emass(k, 1.0)
    m.fix(1)
    m.fix(2)
    m.timestep(1, 1e-4)
    return m


def test_a_chain_of_20000_massless_beams_is_refused_at_once_naming_the_missing_masses():
    model = beam_chain(20000)
    start = time.perf_counter()
    with pytest.raises(SingularMassError, match=r"no element or node carries mass .* all its 60000 degrees "
                                                r"of freedom .* move no mass; add MASS or EMASS") as info:
        spacar.simulate(model)
    assert time.perf_counter() - start < 30.0  # about 1 s; minutes before (a bound, not a benchmark)
    assert "memory" not in str(info.value)


def test_a_large_model_without_mass_is_refused_before_the_assembly():
    """Issue 38, finding 11: under time_limit=1 the same chain ended in "the time limit of 1 s was
    exceeded at t = 0" after 2.7 s (the assembly and a sparse factorization first); the cheap
    cause is now checked before any work."""
    model = beam_chain(20000)
    start = time.perf_counter()
    with pytest.raises(SingularMassError, match="no element or node carries mass"):
        spacar.simulate(model, time_limit=1.0)
    assert time.perf_counter() - start < 5.0  # about 0.4 s (a bound, not a benchmark)


def test_a_small_massless_chain_names_its_degrees_of_freedom_as_before():
    with pytest.raises(SingularMassError, match=r"\[DYNE element 1 \(PLBEAM\) deformation 1\].* move no mass"):
        spacar.simulate(beam_chain(2))


def test_a_large_chain_with_some_masses_is_singular_without_blaming_memory():
    """Too large to name the degrees of freedom without inertia: the counts and what to check."""
    with pytest.raises(SingularMassError, match=r"singular at t = 0: degrees of freedom \(of 6000\) that move no "
                                                r"mass, or dependent constraints; too large to name them") as info:
        spacar.simulate(beam_chain(2000, mass_at={1}))
    assert "memory limit of" not in str(info.value)


def test_a_small_chain_with_some_masses_still_names_the_degrees_of_freedom():
    with pytest.raises(SingularMassError, match=r"DYNE element 2 \(PLBEAM\) deformation"):
        spacar.simulate(beam_chain(2, mass_at={1}))
