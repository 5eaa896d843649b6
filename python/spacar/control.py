"""A digital controller in the loop of a simulation: sampled at a fixed rate, its actuator loads
held constant between samples (zero-order hold); docs/mechatronics.md.

The signals are named generally: a sensor is a coordinate or its rate, ``("x", n, i)`` or
``("xd", n, i)`` (also ``("xdd", n, i)``), an actuator a load on coordinate ``i`` of node ``n``,
``(n, i)``. They are what the keywords OUTX / OUTXP (outputs) and INPUTF (force inputs) of the
state-space models name, so a controller designed on ``spacar.state_space`` reads and writes the
same signals in the same order."""
from __future__ import annotations

import numpy as np

from ._util import finite_time, returned_loads, show
from .errors import InputError

_SENSED = ("x", "xd", "xdd")


def _whole(v) -> bool:
    """A node or coordinate number: an integer, or a float that is one (2.0, not 2.7, NaN or 'a')."""
    if isinstance(v, (bool, np.bool_)):
        return False
    if isinstance(v, (int, np.integer)):
        return True
    return isinstance(v, (float, np.floating)) and bool(np.isfinite(v)) and float(v).is_integer()


class Controller:
    """``fn(t, sensors) -> actuator loads``, called at ``t0, t0 + 1/rate, ...`` with the sensor
    values (an array in the order of ``sensors``) at that time; it returns one load per actuator,
    held until the next sample. The integrator restarts at every sample (the loads jump there),
    so the C++ loop runs without Python between samples.

    After a run, ``log`` holds the samples: ``{"t": (ns,), "sensors": (ns, n_sensors),
    "actuators": (ns, n_actuators)}`` (the last run only).
    """

    def __init__(self, fn, rate: float, sensors, actuators):
        if not callable(fn):
            raise InputError(f"Controller: fn must be a function fn(t, sensors), got {show(fn)}")
        if isinstance(rate, bool) or not isinstance(rate, (int, float, np.integer, np.floating)) \
                or finite_time(rate, "Controller: rate") <= 0:
            raise InputError(f"Controller: rate must be a positive number of samples per second, got {show(rate)}")
        self.fn, self.rate = fn, float(rate)
        for name, items in (("sensors", sensors), ("actuators", actuators)):
            if not isinstance(items, (list, tuple)):
                raise InputError(f"Controller: {name} must be a list of tuples, got {show(items)}")
        self.sensors = [self._sensor(s) for s in sensors]
        self.actuators = [self._actuator(a) for a in actuators]
        if not self.actuators:
            raise InputError("Controller: no actuators")
        self.log = None

    @staticmethod
    def _sensor(s):
        if not (isinstance(s, tuple) and len(s) == 3 and s[0] in _SENSED and _whole(s[1]) and _whole(s[2])):
            raise InputError(f"Controller: a sensor is ('x' | 'xd' | 'xdd', node, coordinate) with whole numbers, "
                             f"got {show(s)}")
        return (s[0], int(s[1]), int(s[2]))

    @staticmethod
    def _actuator(a):
        if not (isinstance(a, tuple) and len(a) == 2 and _whole(a[0]) and _whole(a[1])):
            raise InputError(f"Controller: an actuator is (node, coordinate) with whole numbers, got {show(a)}")
        return (int(a[0]), int(a[1]))

    def _bind(self, coordinate_labels):
        """The on_sample function of the core for a system with these coordinate labels."""
        index = {(int(n), int(i)): g for g, (n, i) in enumerate(coordinate_labels)}
        nx = len(coordinate_labels)
        for what, n, i in self.sensors:
            if (n, i) not in index:
                raise InputError(f"Controller: the sensor {(what, n, i)} names no coordinate of the model")
        for a in self.actuators:
            if a not in index:
                raise InputError(f"Controller: the actuator {a} names no coordinate of the model")
        sensed = [(_SENSED.index(w), index[(n, i)]) for w, n, i in self.sensors]
        acting = np.array([index[a] for a in self.actuators], dtype=int)
        log_t, log_y, log_u = [], [], []

        def on_sample(t, x, xd, xdd):
            state = (x, xd, xdd)
            y = np.array([state[k][g] for k, g in sensed])
            u = returned_loads(self.fn(t, y.copy()), len(acting), "Controller: fn (one load per actuator)", t)
            log_t.append(t)
            log_y.append(y)
            log_u.append(u)
            held = np.zeros(nx)
            np.add.at(held, acting, u)
            return held

        def finish():
            self.log = {"t": np.array(log_t), "sensors": np.array(log_y).reshape(len(log_t), len(sensed)),
                        "actuators": np.array(log_u).reshape(len(log_t), len(acting))}

        return on_sample, finish
