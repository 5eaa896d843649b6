"""The position solves of a simulation follow the integration tolerance (docs/formulation.md §6):
EPSKIN is tightened to 1e-4 of EPSINT and EPSIND, so that Newton's residual is not noise to the
step control. A 16-PLBEAM steel beam spun up by a table from rest (its root's BETA an input):
with the default EPSKIN (1e-5) and EPSINT 1e-7, Radau5 took 7 Jacobians before (the simplified
Newton iteration failing on the noise), with the tightened one a single Jacobian, and the same
tip as a run that sets EPSKIN 1e-12 itself."""
import numpy as np
import spacar
from spacar.compare import models


def spin_up(epskin: float) -> spacar.Results:
    n, t_end = 16, 1.0
    m = models.cantilever(n, ei=175.0, rho_a=0.785, t_end=t_end, n_out=20, eps=1e-7, epskin=epskin)
    m.gravity(0.0, 0.0)
    m.inputx(10001, 1)
    t = np.linspace(0.0, t_end, 41)
    rate = 3.0  # rad/s: the peak rate of a cosine pulse, at 0.5 s; at rest again at 1 s
    angle = 0.5 * rate * (t - np.sin(2.0 * np.pi * t) / (2.0 * np.pi))
    table = spacar.Table(t, angle, kind="cubic")
    return spacar.simulate(m, method="radau5", inputs={(10001, 1): table}, progress=False)


def test_default_epskin_is_no_noise_to_radau():
    loose, tight = spin_up(1e-5), spin_up(1e-12)
    assert loose.stats["jacobians"] <= 2
    assert loose.stats["steps"] <= 1.1 * tight.stats["steps"]
    tip = 17
    np.testing.assert_allclose(loose.node(tip).x[-1], tight.node(tip).x[-1], atol=1e-9)

