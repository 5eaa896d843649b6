"""The energy balance of a simulation: ``res.energy`` (docs/mechatronics.md)."""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from . import _core

KEYS = _core.energy_columns  # kEnergyColumns (simulate.hpp)


class Energy(Mapping):
    """Arrays over the output times: ``kinetic`` (½ ẋᵀMẋ), ``potential`` (of gravity), ``strain``
    (½ eᵀSe of the elastic deformations), ``dissipated`` (∫ ėᵀDė dt of EDAMPP and the other
    damping) and ``external_work`` (∫ of the power of FORCE, TORQUEL, time-dependent loads,
    controllers and the drivers of prescribed inputs). ``total`` = kinetic + potential + strain +
    dissipated − external_work stays at its initial value; ``balance`` is its change."""

    def __init__(self, t, arrays: dict):
        self.t = np.asarray(t, dtype=float)
        self._arrays = {k: np.asarray(arrays[k], dtype=float) for k in KEYS}

    def __getitem__(self, key):
        return self._arrays[key]

    def __iter__(self):
        return iter(KEYS)

    def __len__(self):
        return len(KEYS)

    @classmethod
    def concatenate(cls, energies) -> "Energy":
        """The balance of consecutive blocks: the works of every block (integrated from its start)
        continue from the end of the block before."""
        t = np.concatenate([e.t for e in energies])
        arrays, offset = {k: [] for k in KEYS}, {"dissipated": 0.0, "external_work": 0.0}
        for e in energies:
            for k in KEYS:
                arrays[k].append(e[k] + offset.get(k, 0.0))
            for k in offset:
                offset[k] = arrays[k][-1][-1] if len(arrays[k][-1]) else offset[k]
        return cls(t, {k: np.concatenate(v) for k, v in arrays.items()})

    @property
    def total(self) -> np.ndarray:
        a = self._arrays
        return a["kinetic"] + a["potential"] + a["strain"] + a["dissipated"] - a["external_work"]

    @property
    def balance(self) -> np.ndarray:
        """total − total[0]: zero up to the integration error."""
        return self.total - self.total[0]

    def plot(self, ax=None, balance: bool = True):
        """The five terms (and the balance) against time on a matplotlib axes; returns it."""
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots()
        for k in KEYS:
            ax.plot(self.t, self._arrays[k], label=k.replace("_", " "))
        if balance:
            ax.plot(self.t, self.balance, "k--", label="balance (total − initial)")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("energy [J]")
        ax.legend()
        return ax
