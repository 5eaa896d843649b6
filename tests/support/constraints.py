"""Pinocchio's constrained dynamics with a rigid 3-D point constraint: the independent reference of
the closed-loop tests (tests/peers/test_closed_loops.py, tests/api/test_urdf_loops.py)."""
from __future__ import annotations

import numpy as np


def constrained(model, joint1, point1, joint2, point2):
    """A solver q, v → q̈ of Pinocchio's constrained dynamics of `model` (no joint torques) with a
    3-D point constraint between point1 (in joint1's frame) and point2 (in joint2's)."""
    import pinocchio as pin

    data = model.createData()
    cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, joint1, pin.SE3(np.eye(3), point1),
                                  joint2, pin.SE3(np.eye(3), point2), pin.ReferenceFrame.LOCAL)
    cms = pin.StdVec_RigidConstraintModel()
    cms.append(cm)
    cds = pin.StdVec_RigidConstraintData()
    cds.append(cm.createData())
    pin.initConstraintDynamics(model, data, cms, cds)
    settings = pin.ProximalSettings(1e-14, 1e-12, 100)

    def accelerations(q, v):
        return pin.constraintDynamics(model, data, q, v, np.zeros(model.nv), cms, cds, settings)

    return accelerations
