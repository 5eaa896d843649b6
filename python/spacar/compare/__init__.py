"""Cross-checks against exudyn and Pinocchio: converters that build the equivalent peer model of
a spacar model, run it, and return side-by-side arrays.

* :mod:`spacar.compare.pinocchio` — kinematic trees of rigid links (CRBA mass matrix, ABA
  accelerations, trajectories by integrating ABA).
* :mod:`spacar.compare.exudyn` — rigid bodies with revolute/spherical joints, joint springs,
  closed loops, sliders, prescribed crank rotation, and flexible planar beams as ANCF cable
  elements; trajectories mapped back onto spacar's nodal coordinates.
* :mod:`spacar.compare.exudyn_static` — static equilibria of planar flexure models (beams as
  exudyn's geometrically exact 2D beams, SolveStatic).

Both need the optional extra ``compare`` (``pip install "spacar[compare]"``, from a clone
``pip install ".[compare]"``: exudyn and pin);
the submodules import their peer on first use, so ``import spacar.compare`` always works.
What each converter supports is listed in its module docstring and in docs/comparison.md; a
model outside that raises :class:`UnsupportedModelError` naming the node or element concerned;
a peer run that reports success with a non-finite or diverged state raises
:class:`PeerResultError`.
"""
from ._topology import PeerResultError, Topology, UnsupportedModelError, analyse

__all__ = ["PeerResultError", "UnsupportedModelError", "Topology", "analyse"]
