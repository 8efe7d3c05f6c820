"""Your own robot from its URDF and a CSV log: the quickstart of the docs, end to end.

The URDF shipped with dynid stands for your robot's, a simulated log for your robot's log (time, six joint angles,
six joint torques); the config is the one a user writes, and ``dynid identify`` runs on it as on a real log.
"""

import subprocess
import sys
from importlib import resources

import numpy as np

import dynid

urdf = resources.files("dynid.model") / "robots" / "ur10e.urdf"            # your robot's URDF
log = dynid.simulated_log(dynid.load_robot(str(urdf)), seconds=60, rng=3)  # your robot's log
names = ["t"] + [f"q{j}" for j in range(1, 7)] + [f"tau{j}" for j in range(1, 7)]
np.savetxt("log.csv", np.column_stack([log.t, log.q, log.tau]), delimiter=",", header=",".join(names), comments="")

with open("arm.toml", "w") as f:
    f.write(f'''robot = "{urdf}"
data_root = "."

[identification]
file = "log.csv"
header = true
time = {{ column = "t" }}
positions = {{ columns = ["q1", "q2", "q3", "q4", "q5", "q6"] }}
torques = {{ columns = ["tau1", "tau2", "tau3", "tau4", "tau5", "tau6"] }}
''')

done = subprocess.run([sys.executable, "-m", "dynid", "identify", "arm.toml", "--out", "arm-identified", "--no-figures"])
sys.exit(done.returncode)
