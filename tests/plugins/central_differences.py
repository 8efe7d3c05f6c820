"""A new preprocessing strategy in one file: no filter at all, derivatives by central differences, every row kept.
Registered as "central_differences_test"."""

from dataclasses import replace

import numpy as np

from dynid.dynamics.regressor import regressor
from dynid.preprocessing.prepared import PreparedData
from dynid.preprocessing.strategies import Strategy, register_strategy


class CentralDifferences(Strategy):
    """Positions as logged, velocities and accelerations by central differences (numpy.gradient)."""

    def prepare(self, recording, settings, strict=True):
        step = 1.0 / recording.rate
        q = np.asarray(recording.q, dtype=float)
        dq = np.gradient(q, step, axis=0) if recording.dq is None else np.asarray(recording.dq, dtype=float)
        ddq = np.gradient(dq, step, axis=0)
        s = replace(settings, decimation=1, min_speed=0.0, rest_velocity=0.0, trim=0.0, parallel_cutoff=0.0,
                    derivation="central differences, no filter")
        return PreparedData(recording.name, recording.t, q, dq, ddq, np.asarray(recording.tau, dtype=float), recording.rate, s,
                            tuple(recording.warnings))

    def chunks(self, robot, base, data, progress=None, standard=False):
        y = regressor(robot, data.q, data.dq, data.ddq, columns=None if standard else base.independent)
        yield np.arange(data.t.shape[0]), y, data.tau, np.ones(data.tau.shape, dtype=bool)


register_strategy("central_differences_test", CentralDifferences, replace=True)
