"""The paper's preprocessing (§3.3) as a strategy: derivatives from a Fourier fit of the positions on the excitation's
harmonics, and eq. 17 applied to the torques **and** to every regressor column.

Smoothing the torques alone would make measured and modelled torque differ at each velocity reversal, where the
Coulomb column steps; eq. 17 on both keeps them comparable (parallel filtering). The whole log is smoothed at once
(in memory): the paper's recordings are seconds long.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..dynamics.regressor import regressor
from ..exceptions import ConfigError, DataError
from .fourier_fit import fourier_fit_derivatives
from .prepared import PreparedData
from .settings import Preprocessing
from .smoothing import five_point_cubic_smoothing
from .strategies import Strategy


class PaperSmoothing(Strategy):
    """Fourier-fit derivatives and eq. 17 smoothing (``settings.smoothing_passes`` times) of the torques and the
    regressor; every row kept, no decimation."""

    name = "paper"
    needs_harmonics = True

    def prepare(self, recording, settings: Preprocessing, strict: bool = True) -> PreparedData:
        """Positions, velocities and accelerations of the series fitted on ``settings.fourier``'s harmonics.

        Parameters
        ----------
        recording : dynid.io.logs.datasets.Recording
        settings : Preprocessing
            ``fourier`` = (ω_f [rad/s], harmonics) is required (``[preprocessing] excitation`` in a config).
        strict : bool
            Unused: nothing depends on the rate.

        Returns
        -------
        PreparedData

        Raises
        ------
        ConfigError
            No excitation harmonics, or a negative number of passes.
        DataError
            Fewer than 5 samples (eq. 17's window).
        """
        if settings.fourier is None:
            raise ConfigError("preprocessing.strategy = \"paper\": the excitation's harmonics are needed for the Fourier fit "
                              "(preprocessing.excitation = the excitation.json the robot ran)", field="preprocessing.excitation")
        if settings.smoothing_passes < 0:
            raise ConfigError(f"preprocessing.smoothing_passes: expected an integer >= 0, got {settings.smoothing_passes}",
                              field="preprocessing.smoothing_passes")
        if recording.n_samples < 5:
            raise DataError(f"{recording.label}: {recording.n_samples} samples: eq. 17 needs at least 5")
        omega_f, harmonics = settings.fourier
        q, dq, ddq, _ = fourier_fit_derivatives(recording.t, np.asarray(recording.q), omega_f, harmonics)
        band = omega_f * harmonics / (2 * np.pi)
        s = replace(settings, band=float(band), decimation=1, parallel_cutoff=0.0, position_cutoff=0.0, velocity_cutoff=0.0,
                    min_speed=0.0, trim=0.0, rest_velocity=0.0, warnings=(),
                    derivation=f"positions, velocities and accelerations from the Fourier fit on {harmonics} harmonics of "
                               f"{omega_f:.4g} rad/s; eq. 17 applied {settings.smoothing_passes} time(s) to the torques and "
                               "every regressor column")
        return PreparedData(recording.name, recording.t, q, dq, ddq, np.asarray(recording.tau, dtype=float), recording.rate, s,
                            tuple(recording.warnings), drive_gains=getattr(recording, "drive_gains", None))

    def chunks(self, robot, base, data, progress=None, standard=False):
        """One block: the whole log, its regressor and torques smoothed alike by eq. 17; every row kept.

        The Coulomb column uses the plain sign of the velocity (see :meth:`Strategy.chunks`).

        Parameters
        ----------
        robot : Robot
        base : BaseParameters
        data : PreparedData
            From :meth:`prepare`.
        progress : callable, optional
            ``progress(done, total)`` in samples.
        standard : bool
            Give the standard regressor instead of the base one.

        Yields
        ------
        tuple
            ``(index, y, tau, keep)`` as :meth:`Strategy.chunks`.
        """
        passes = data.settings.smoothing_passes
        y = five_point_cubic_smoothing(regressor(robot, data.q, data.dq, data.ddq, columns=None if standard else base.independent), passes)
        tau = five_point_cubic_smoothing(data.tau, passes)
        n = data.t.shape[0]
        if progress is not None:
            progress(n, n)
        yield np.arange(n), y, tau, np.ones(tau.shape, dtype=bool)
