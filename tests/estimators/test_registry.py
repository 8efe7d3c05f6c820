"""The estimators side by side (fit_methods): an interrupted caller does not wait for the box searches."""

import _thread
import threading

import numpy as np
import pytest

from dynid.estimators.registry import FitData, SearchBudget, fit_methods


def test_an_interrupted_caller_stops_the_box_searches_instead_of_waiting_for_their_end():
    rng = np.random.default_rng(0)
    n, n_base, samples = 3, 10, 200
    w = rng.normal(size=(samples * n, n_base))
    beta = rng.normal(size=n_base)
    tau = w @ beta + rng.normal(size=samples * n)
    data = FitData(w, tau, n, np.column_stack([beta - 5.0, beta + 5.0]), base=None)
    budget = SearchBudget(colony_size=30, limit=15, maxiter=5_000)
    pso_iterations = budget.evaluations // budget.colony_size - 1  # PSO runs them all: seconds
    last, fired, lock, searchers = {}, [], threading.Lock(), set()  # the lock: one interrupt, whichever reports first

    def progress(key, iteration, best):
        if iteration is None:
            return
        with lock:
            searchers.add(threading.current_thread())
            last[key] = iteration
            if len(last) == 2 and min(last.values()) >= 10 and not fired:  # as Ctrl-C while both search
                fired.append(True)
                _thread.interrupt_main()

    with pytest.raises(KeyboardInterrupt):
        fit_methods(("de", "pso"), data, budget, {"de": np.random.default_rng(1), "pso": np.random.default_rng(2)}, progress)
    for t in searchers:  # joined by fit_methods, unless Ctrl-C came while it was starting a thread
        t.join(timeout=60)
    assert set(last) == {"de", "pso"} and not any(t.is_alive() for t in searchers)  # both searched, both ended
    assert last["pso"] < pso_iterations // 4  # stopped at its next iteration, not run to its end
