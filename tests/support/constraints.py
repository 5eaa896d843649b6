"""Pinocchio's constrained dynamics with a rigid 3-D point constraint: the independent reference of
the closed-loop tests (tests/peers/test_closed_loops.py, tests/api/test_urdf_loops.py)."""
from __future__ import annotations


def constrained(model, joint1, point1, joint2, point2):
    """A solver q, v → q̈ of Pinocchio's constrained dynamics (spacar.compare.pinocchio)."""
    from spacar.compare.pinocchio import point_constrained

    return point_constrained(model, joint1, point1, joint2, point2)
