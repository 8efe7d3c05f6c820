"""Identify a robot from arrays, without a config file: a UR10e motion simulated with Pinocchio's RNEA
(plus friction and current noise), then dynid's default pipeline on (t, q, τ)."""

import numpy as np

import dynid

robot = dynid.load_robot("ur10e")
rng = np.random.default_rng(0)
t = np.arange(0, 40, 0.004)  # 40 s at 250 Hz
k = np.arange(1, 5)[:, None, None]
a = rng.uniform(-0.6, 0.6, (4, 1, 6)) / k
q = (a * np.sin(2 * np.pi * 0.1 * k * t[None, :, None] + rng.uniform(0, 6, (4, 1, 6)))).sum(0)
dq, ddq = np.gradient(q, t, axis=0), np.gradient(np.gradient(q, t, axis=0), t, axis=0)
tau = dynid.rnea_torques(robot, q, dq, ddq) + 2.0 * np.sign(dq) + 1.0 * dq + rng.normal(0, 0.05, q.shape)

result = dynid.identify_from_arrays(robot, t, q, tau, estimators=("ols",))
print(dynid.summary(result, width=100))  # what dynid identify prints: settings, base parameters with σ, fit per joint
print("relative error per joint on the fit (%):", np.round(result.fit.metrics()["dynid OLS"]["relative_error"], 2))
