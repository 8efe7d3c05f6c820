"""The estimators side by side (fit_methods): an interrupted caller does not wait for the box searches."""

import subprocess
import sys
import textwrap

SCENARIO = textwrap.dedent('''
    import _thread, signal, threading
    import numpy as np
    # Ctrl-C raises KeyboardInterrupt here even when this process was started with SIGINT ignored (a background job
    # of a non-interactive shell, as a CI runner may start it): interrupt_main does nothing where SIGINT is ignored
    signal.signal(signal.SIGINT, signal.default_int_handler)
    from dynid.estimators.fitting import fit_methods
    from dynid.estimators.problem import FitData, SearchBudget

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
            if len(last) == 2 and last["pso"] >= 10 and not fired:  # as Ctrl-C while PSO searches (DE may be done)
                fired.append(True)
                _thread.interrupt_main()

    try:
        fit_methods(("de", "pso"), data, budget, {"de": np.random.default_rng(1), "pso": np.random.default_rng(2)},
                    progress=progress, workers=2)
        print("not interrupted", last, fired)
    except KeyboardInterrupt:
        for t in searchers:  # joined by fit_methods, unless Ctrl-C came while it was starting a thread
            t.join(timeout=60)
        print(sorted(last), any(t.is_alive() for t in searchers), last["pso"], pso_iterations)
''')


def test_an_interrupted_caller_stops_the_box_searches_instead_of_waiting_for_their_end():
    # in a process of its own: Ctrl-C (interrupt_main) reaches the main thread, which a test runner may not run tests in
    out = subprocess.run([sys.executable, "-c", SCENARIO], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    words = out.stdout.split()
    assert words[:2] != ["not", "interrupted"], out.stdout
    names, alive, pso_last, pso_total = out.stdout.rsplit("]", 1)[0] + "]", words[-3], int(words[-2]), int(words[-1])
    assert names == "['de', 'pso']" and alive == "False"  # both searched, both ended
    assert pso_last < pso_total // 4  # stopped at its next iteration, not run to its end
