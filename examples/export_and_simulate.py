"""Identify with physically consistent least squares, export the model as a URDF, load it in Pinocchio
and simulate it: the exported URDF gives the torques dynid predicts (inverse dynamics), and forward
dynamics (ABA) with its joint damping runs from rest."""

import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin

import dynid

robot = dynid.load_robot("er16")
rng = np.random.default_rng(1)
t = np.arange(0, 30, 0.005)
k = np.arange(1, 5)[:, None, None]
q = (rng.uniform(-0.5, 0.5, (4, 1, 6)) / k * np.sin(2 * np.pi * 0.1 * k * t[None, :, None] + rng.uniform(0, 6, (4, 1, 6)))).sum(0)
dq, ddq = np.gradient(q, t, axis=0), np.gradient(np.gradient(q, t, axis=0), t, axis=0)
tau = dynid.rnea_torques(robot, q, dq, ddq) + rng.normal(0, 0.2, q.shape)

result = dynid.identify_from_arrays(robot, t, q, tau, estimators=("ols", "sdp"))
sdp = result.estimates["dynid SDP"]
urdf = Path(tempfile.mkdtemp()) / "er16_identified.urdf"
urdf.write_text(dynid.urdf_from_robot(robot, sdp.standard))
model = pin.buildModelFromUrdf(str(urdf))
data = model.createData()

# inverse dynamics of the exported model against dynid's prediction with the identified base parameters
qs, dqs, ddqs = (rng.uniform(-1, 1, (5, 6)) for _ in range(3))
exported = np.array([pin.rnea(model, data, a, b, c) for a, b, c in zip(qs, dqs, ddqs)])
exported += model.damping * dqs + model.friction * np.sign(dqs)
predicted = result.base.base_observation(dynid.regressor(robot, qs, dqs, ddqs)) @ sdp.params
print("largest difference, exported URDF vs dynid (N·m):", float(np.abs(exported - predicted).max()))

# forward dynamics: the arm released from rest, 0.5 s with viscous joint damping
x, v, h = np.zeros(6), np.zeros(6), 1e-3
for _ in range(500):
    a = pin.aba(model, data, x, v, -model.damping * v)
    v, x = v + h * a, x + h * (v + h * a)
print("after 0.5 s from rest, joint angles (rad):", np.round(x, 3))
