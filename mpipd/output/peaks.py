"""Per-point running peaks over every step (not over saved frames).

A peak field named in ``[output] fields`` is kept up to date after every step
and written at each frame (the frame then holds the peak over all steps up to
it; the last frame, over the whole run):

    peak_pressure   max_t of -tr(sigma)/3 (Pa) for solid points, of the JWL pressure
                    for gas points
    peak_sigma_rr   max_t of -sigma_rr (Pa, compression positive), radial about the z
                    axis through ``[output] peak_center``
    peak_speed      max_t |v| (m/s)

Only a scene that asks for one of them pays for the (one pass over the points)
update; they start at 0 (the reference state is unstressed and at rest).
"""
from __future__ import annotations

import numpy as np

from ..kernels.energy import update_peaks
from ..kernels.layout import GD_P
from ..state import AUX

NAMES = ("peak_pressure", "peak_sigma_rr", "peak_speed")


class Peaks:
    def __init__(self, sim, output):
        n = sim.points.n_owned
        self.on = any(f in NAMES for f in output.fields)
        self.center = tuple(output.peak_center)
        size = n if self.on else 0
        self.arrays = {k: np.zeros(size) for k in NAMES}
        self._empty = np.zeros(0, np.int64)
        self._nogas = np.zeros(0)

    def register(self, state):
        """The peak arrays in the State (owner "peaks"), checkpointed and offered as
        output fields when the scene asks for them."""
        for key, arr in self.arrays.items():
            state.add(key, "peaks", arr, checkpoint=self.on, output=key)
        state.add("peaks_empty", "peaks", self._empty, rows=AUX)
        state.add("peaks_nogas", "peaks", self._nogas, rows=AUX)

    def sample(self, sim):
        if not self.on:
            return
        c, a = sim.corr, self.arrays
        gas = sim.gas
        gidx = gas.gas_idx if gas is not None else self._empty
        gp = gas.gd[:, GD_P] if gas is not None else self._nogas
        update_peaks(sim.points.x, sim.v, c.sigma, c.R, gidx, gp, self.center[0],
                     self.center[1], a["peak_pressure"], a["peak_sigma_rr"], a["peak_speed"])
