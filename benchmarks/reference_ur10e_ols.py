"""Reference for the benchmark table: the UR10e estimation as a plain script (numpy, SciPy, Pinocchio),
what a user would write by hand: zero-phase filters, Pinocchio's joint-torque regressor in a loop,
friction columns, least squares. Prints the residual RMS per joint. Usage: reference_ur10e_ols.py DATA_ROOT"""

import sys

import numpy as np
import pinocchio as pin
from scipy import signal

root = sys.argv[1]
raw = np.loadtxt(f"{root}/identification_data/ur-20_02_10-30sec_12harm.csv", delimiter=",")[634:3510]
t, q, dq, cur = raw[:, 0], raw[:, 1:7], raw[:, 7:13], raw[:, 13:19]
gains = np.array([10.0, 10.6956, 8.4566, 9.0029, 9.48, 10.1232])
grid = np.arange(t[0], t[-1], 0.01)
q, dq, tau = (np.column_stack([np.interp(grid, t, x[:, j]) for j in range(6)]) for x in (q, dq, cur * gains))
b, a = signal.butter(5, 0.15)
dq = signal.filtfilt(b, a, dq, axis=0)
ddq = np.gradient(dq, 0.01, axis=0)
tau = signal.filtfilt(*signal.butter(5, 0.2), tau, axis=0)
model = pin.buildModelFromUrdf(f"{root}/urdf/ur10e.urdf")
data = model.createData()
rows = []
for k in range(len(grid)):
    y = pin.computeJointTorqueRegressor(model, data, q[k], dq[k], ddq[k])
    rows.append(np.hstack([y, np.diag(ddq[k]), np.diag(np.sign(dq[k])), np.diag(dq[k]), np.eye(6)]))
w = np.vstack(rows)
theta, *_ = np.linalg.lstsq(w, tau.ravel(), rcond=None)
print("residual RMS per joint (N·m):", np.sqrt(((tau.ravel() - w @ theta).reshape(-1, 6) ** 2).mean(0)).round(3))
