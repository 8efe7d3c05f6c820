"""``python -m dynid.warm_up`` (run by ``make`` after installing) passes through every compiled kernel, so
their machine code is in numba's cache before the first command."""

import os
import subprocess
import sys

CHECK = """
import numba
from dynid.warm_up import warm_up
warm_up()
import dynid.dynamics._regressor_kernel as r, dynid.estimators._objective_kernel as o, dynid.estimators.recursive as rls
import dynid.simulation._step_kernel as cl, dynid.preprocessing._filter_kernel as fk
kernels = {f"{m.__name__}.{k}": v for m in (r, o, rls, cl, fk) for k, v in vars(m).items()
           if isinstance(v, numba.core.registry.CPUDispatcher) and v.targetoptions.get("inline", "never") == "never"}
assert len(kernels) >= 12 and {"dynid.preprocessing._filter_kernel.sections", "dynid.preprocessing._filter_kernel.symmetric"} <= set(kernels), sorted(kernels)
missing = [k for k, v in kernels.items() if not v.signatures]
assert not missing, missing
print(len(kernels))
"""


def test_warm_up_compiles_every_kernel_into_the_cache(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", CHECK], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    index = [f for _, _, files in os.walk(tmp_path) for f in files if f.endswith(".nbi")]
    assert len(index) == int(out.stdout.split()[-1])  # one cache index per kernel
