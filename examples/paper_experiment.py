"""The paper's experiment in a few lines: the simulated ER-16 (joints 1-3), identified by least squares
and by the artificial bee colony of §3.1, validated on the second trajectory (eq. 18)."""

import numpy as np

import dynid

run = dynid.run_paper_experiment(dynid.PaperExperimentConfig(estimators=("ols", "abc"), bootstrap=0, duration=10.0))
print(f"{'method':8s} {'F (eq. 9)':>10s} {'param. error %':>15s} {'validation ρ (eq. 18)':>24s}")
for key, m in run.estimates.items():
    error = 100 * np.linalg.norm(m.params - run.truth) / np.linalg.norm(run.truth)
    rho = m.metrics["correlation"]["validation"]
    print(f"{key:8s} {m.objective:10.4f} {error:15.3f} {' '.join(f'{r:.4f}' for r in rho):>24s}")
