"""Monte Carlo study: the Dask path (LocalCluster), determinism, and the Cramér–Rao bound."""

import numpy as np
import pytest

from dynid.exceptions import ConfigError
from dynid.studies.montecarlo import MonteCarloConfig, _prepare, run_montecarlo, simulate_realisation

SMALL = MonteCarloConfig(noise_levels=(0.05, 0.4), realisations=12, estimators=("ols", "wls", "abc"), duration=8.0,
                         rate=100.0, maxiter=3)


@pytest.fixture(scope="module")
def study():
    return run_montecarlo(SMALL, workers=2)


def test_local_cluster_runs_every_task_and_matches_a_direct_call(study):
    assert "2 Dask workers" in study.cluster
    assert study.estimates.shape == (2, 12, 3, 21) and np.all(np.isfinite(study.estimates))
    setup = _prepare(SMALL)
    for li, r in ((0, 0), (1, 7)):
        direct = simulate_realisation(setup, li, r)["params"]
        np.testing.assert_array_equal(direct, study.estimates[li, r])  # independent of scheduling


def test_ols_spread_follows_the_cramer_rao_bound(study):
    """OLS is efficient under Gaussian noise: std over realisations ≈ √CRB (12 realisations: ±~40 %),
    and both grow linearly with the noise level."""
    stats = study.statistics()
    ratio = stats["ols"]["std_over_crb"]
    assert 0.6 < np.median(ratio[0]) < 1.4 and 0.6 < np.median(ratio[1]) < 1.4
    np.testing.assert_allclose(study.crb_std[1] / study.crb_std[0], 8.0)
    assert np.median(stats["ols"]["std"][1] / stats["ols"]["std"][0]) > 4.0
    assert np.all(stats["ols"]["failures"] == 0)


def test_cramer_rao_bound_is_the_inverse_fisher_information(study):
    """Independent check of the bound: inverse of Σ_k WᵀΣ⁻¹W built row by row with the drive gains."""
    from dynid.dynamics.regressor import observation_matrix

    setup = _prepare(SMALL)
    q, dq, ddq = setup.trajectory.evaluate(setup.t)
    w = setup.base.base_observation(observation_matrix(setup.robot, q, dq, ddq))
    sigma_tau = np.tile(0.05 * np.asarray(setup.robot.drive_gains), setup.t.size)
    crb = np.linalg.inv(w.T @ (w / sigma_tau[:, None] ** 2))
    np.testing.assert_allclose(study.crb_std[0], np.sqrt(np.diag(crb)), rtol=1e-8)


def test_same_seed_same_study(study):
    again = run_montecarlo(MonteCarloConfig(**{**SMALL.__dict__, "realisations": 3}), workers=1)
    np.testing.assert_array_equal(again.estimates, study.estimates[:, :3])
    d = study.to_dict()
    assert d["estimates"]["ols"]["levels"][1]["noise_level_A"] == 0.4
    assert set(d["estimates"]["abc"]["levels"][0]) >= {"bias", "std", "std_over_crb", "failures"}


@pytest.mark.parametrize("kwargs, message", [
    ({"noise_levels": ()}, "noise_levels"),
    ({"noise_levels": (0.0,)}, "noise_levels"),
    ({"realisations": 1}, "realisations"),
    ({"estimators": ("ols", "magic")}, "estimators"),
    ({"joints": 9}, "joints"),
])
def test_bad_settings(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        run_montecarlo(MonteCarloConfig(**{**SMALL.__dict__, **kwargs}), workers=1)


def test_unreachable_scheduler_is_a_one_line_error():
    from dynid.runtime.cluster import dask_client

    with pytest.raises(ConfigError, match="cannot reach the Dask scheduler"):
        with dask_client(scheduler="tcp://127.0.0.1:9", connect_timeout=1.0):
            pass


def test_scheduler_address_path_gives_the_same_study(study):
    """The --scheduler path: a client to an already running cluster, given by its address."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        remote = run_montecarlo(MonteCarloConfig(**{**SMALL.__dict__, "realisations": 2}), scheduler=cluster.scheduler_address)
    assert cluster.scheduler_address in remote.cluster
    np.testing.assert_array_equal(remote.estimates, study.estimates[:, :2])


def test_the_summary_names_the_estimator_nearest_the_bound_at_each_level(study):
    from dynid.report.summaries import summary

    text = " ".join(summary(study, width=200).split())
    stats = study.statistics()
    for li, level in enumerate(SMALL.noise_levels):
        scores = {k: np.nanmedian(stats[k]["rmse"][li] / study.crb_std[li]) for k in SMALL.estimators}
        best = min(scores, key=scores.get)
        assert f"{level:g} A: {best.upper()} ({scores[best]:.3g}× √CRB)" in text


def test_the_local_clusters_tasks_start_no_thread_pools():
    """The local cluster's workers share the machine's cores, one task each: dynid's own thread pools take one core
    in a task (they took every core in each worker, and a task starting one hung once in a test run)."""
    import os

    from dynid.runtime.cluster import dask_client
    from dynid.runtime.threads import cores

    assert cores() == len(os.sched_getaffinity(0)) >= 2  # this process: every core it may use
    with dask_client(workers=1) as client:
        assert client.submit(cores, pure=False).result() == 1


@pytest.mark.parametrize("method,preloaded", [(None, True), ("forkserver", False)])
def test_the_local_clusters_workers_are_forked_from_a_server_that_imported_the_tasks_modules(method, preloaded):
    """A local cluster's worker is forked from a server that imported the modules its tasks need once (a fresh process
    here: the server is the process's first cluster's): it does not import them again, as each worker started as a new
    interpreter (Dask's default) did. A Dask configuration naming its own start method is kept (its server, Dask's
    own, has not imported them)."""
    import os
    import subprocess
    import sys

    script = ("from dynid.runtime.cluster import dask_client\n"
              "with dask_client(workers=1, preload=('cvxpy',)) as client:\n"
              "    print(client.submit(lambda: 'cvxpy' in __import__('sys').modules, pure=False).result())\n")
    env = {k: v for k, v in os.environ.items() if k != "DASK_DISTRIBUTED__WORKER__MULTIPROCESSING_METHOD"}
    if method is not None:
        env["DASK_DISTRIBUTED__WORKER__MULTIPROCESSING_METHOD"] = method
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300, env=env)
    assert p.returncode == 0, p.stderr
    assert p.stdout.split() == [str(preloaded)], p.stdout
