"""Benchmark: the cost of one evaluation of eq. 9 (the paper's sum of weighted absolute deviations) in the searches
of `dynid run` (issue "The main job fast and faithful", item 2), on `dynid run`'s own identification problem
(the decimated base observation matrix of the ER-16 at the paper's settings).

Three ways, timed in the same run, each per candidate evaluated:

* reference: one candidate at a time, ``paper_objective(tau - W @ x)`` (a matrix-vector product, a subtraction, an
  absolute value and a weighted sum over every row: what a search that calls its objective per candidate pays);
* a population (DE and PSO: a generation of K candidates): ``LinearAbsoluteObjective(W, tau)(X)``, X (p, K), row
  blocks of W·X in BLAS with each block's weighted absolute residuals summed in one compiled pass;
* a coordinate move (the artificial bee colony of §3.1 changes one parameter of a food source): the new residual is
  ``r - delta·W[:, j]``, F summed in the same compiled pass (``LinearAbsoluteObjective.move``).

Each is the best of several repeats after a warm-up. BLAS limited to one thread (as dynid runs its searches side
by side on the cores). ``python benchmarks/bench_objective.py`` (``make bench`` runs it).
"""

from __future__ import annotations

import numpy as np
from threadpoolctl import threadpool_limits
from timing import best_of  # benchmarks/timing.py

from dynid.estimators.base import LinearAbsoluteObjective, paper_objective
from dynid.studies.paper import PaperExperimentConfig, run_paper_experiment

K = 60          # candidates per population (the ABC's colony of 30 food sources twice, DE's 15 × p)
MOVES = 2000
REPEATS = 7


def main() -> None:
    run = run_paper_experiment(PaperExperimentConfig(estimators=("ols",)))
    w, tau, n = run.identification.w_base, run.identification.tau.ravel(), run.config.joints
    m, p = w.shape
    rng = np.random.default_rng(0)
    x = rng.standard_normal((p, K))
    f = LinearAbsoluteObjective(w, tau, n)
    with threadpool_limits(1):
        per_candidate = best_of(lambda: [paper_objective(tau - w @ x[:, k], n) for k in range(K)], REPEATS) / K
        population = best_of(lambda: f(x), REPEATS) / K
        _, r = f.start(x[:, 0])
        js = rng.integers(0, p, MOVES)
        deltas = rng.standard_normal(MOVES)
        move = best_of(lambda: [f.move(r, int(j), float(d)) for j, d in zip(js, deltas)], REPEATS) / MOVES
    same = np.allclose(f(x), [paper_objective(tau - w @ x[:, k], n) for k in range(K)], rtol=1e-12)
    print(f"eq. 9 on dynid run's problem: {m} rows × {p} base parameters; one thread")
    print(f"reference, one candidate at a time: {1e6 * per_candidate:8.1f} µs per candidate")
    print(f"a population of {K} (DE, PSO):      {1e6 * population:8.1f} µs per candidate  "
          f"({per_candidate / population:.1f}× faster; same values: {same})")
    print(f"a coordinate move (ABC):            {1e6 * move:8.1f} µs per candidate  ({per_candidate / move:.1f}× faster)")


if __name__ == "__main__":
    main()
