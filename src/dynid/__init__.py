"""dynid: dynamic model identification of industrial robot arms.

The package follows the procedure of Ding et al., "Dynamic Model Identification for 6-DOF
Industrial Robots" (the ER-16 paper): linear model (eqs. 1-6), Fourier excitation (eq. 14-15),
torques from currents (eq. 16), smoothing (eq. 17), artificial bee colony and least-squares
estimation (eqs. 7-13) and validation by the correlation coefficient (eq. 18).
"""

__version__ = "0.1.0"
