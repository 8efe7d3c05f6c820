"""Work spread over a Dask cluster: a client to a scheduler or a new local cluster, and a map of seeded tasks whose
results are handed back as they finish (the Monte Carlo and closed-loop studies, fleet identification)."""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from ..exceptions import ConfigError
from ..plugins import share_with
from .extras import require
from .threads import ONE_CORE_ENV


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None, connect_timeout: float = 10.0,
                extra: str = "montecarlo", what: str = "dynid montecarlo", preload: tuple[str, ...] = ()):
    """A Dask client to a scheduler, or to a new local cluster.

    Parameters
    ----------
    scheduler : str, optional
        An address like ``tcp://host:8786``; default: a new :class:`distributed.LocalCluster`.
    workers : int, optional
        Single-threaded worker processes of the local cluster (default: the local cores); dynid's own thread pools
        take one core in each (:data:`dynid.runtime.threads.ONE_CORE_ENV`).
    connect_timeout : float [s]
        Time the scheduler is given to answer.
    extra, what : str
        The extra that installs Dask and what needs it, for the message when it is missing.
    preload : tuple of str
        Modules the tasks import: a local cluster's workers are forked from a server that imported them once
        (:func:`_forked_workers`), not each started as a new interpreter that imports them again.

    Yields
    ------
    distributed.Client

    Raises
    ------
    ConfigError
        The scheduler cannot be reached, ``workers`` < 1, or Dask is not installed.
    """
    require("distributed", extra, what)
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout=f"{connect_timeout}s")
        except (OSError, TimeoutError) as exc:
            raise ConfigError(f"scheduler {scheduler}: cannot reach the Dask scheduler ({exc})", field="scheduler") from None
        with client:
            share_with(client)
            yield client
        return
    n = workers if workers is not None else (os.cpu_count() or 1)
    if n < 1:
        raise ConfigError(f"workers must be at least 1, got {workers}", field="workers")
    # the workers share the machine's cores, one task each: no thread pools inside a task (they oversubscribed the
    # cores, and a task starting one hung once against distributed's garbage-collection callback in a test run)
    with _forked_workers(preload), LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                                silence_logs=logging.ERROR, env={ONE_CORE_ENV: "1"}) as cluster, \
            Client(cluster) as client:
        share_with(client)
        yield client


@contextlib.contextmanager
def _forked_workers(preload: tuple[str, ...]):
    """Dask's worker processes started by the ``forkserver`` method, where the platform has it: a server process that
    imported ``preload`` (and Dask, NumPy) forks each worker, so that a worker does not start a new interpreter and
    import dynid and its libraries again (Dask's default ``spawn`` did so for every worker of every cluster). The
    server lives as long as this process and keeps the modules of the first cluster's ``preload``. A worker's
    environment (:data:`dynid.runtime.threads.ONE_CORE_ENV`) is set by Dask's nanny in the worker itself, as with
    ``spawn``. A Dask configuration that names another method than its default (``spawn``) is kept."""
    import dask

    if (dask.config.get("distributed.worker.multiprocessing-method") != "spawn"
            or "forkserver" not in multiprocessing.get_all_start_methods()):
        yield
        return
    from distributed.utils import get_mp_context

    with dask.config.set({"distributed.worker.multiprocessing-method": "forkserver"}):
        get_mp_context().set_forkserver_preload(["distributed", "numpy", *preload])  # Dask's own list replaced
        yield


def map_realisations(function: Callable, setup, keys: list[tuple[int, int]], store: Callable, scheduler: str | None = None,
                     workers: int | None = None, what: str = "dynid montecarlo",
                     progress: Callable[[int, int], None] | None = None) -> str:
    """Run ``function(setup, *key)`` for every key on a Dask cluster, ``setup`` sent once to every worker, and hand each
    result to ``store(key, result)`` as it arrives.

    Parameters
    ----------
    function : callable
        ``function(setup, i, j) -> result``, seeding its own generators from its arguments.
    setup : object
        What every task shares.
    keys : list of (int, int)
    store : callable
        ``store(key, result)``, called in the order the tasks finish.
    scheduler, workers :
        As :func:`dask_client`.
    what : str
        The command, for the message when Dask is missing.
    progress : callable, optional
        ``progress(done, total)``.

    Returns
    -------
    str
        The cluster the tasks ran on.

    Raises
    ------
    ConfigError
        From :func:`dask_client`.
    """
    from distributed import as_completed

    with dask_client(scheduler, workers, what=what, preload=(function.__module__,)) as client:
        cluster = f"{len(client.scheduler_info()['workers'])} Dask workers at {client.scheduler.address}"
        # a key of its own, not the content's hash: a second study of the same setup in one process (another test,
        # another run) scattered the same key, and its release cancelled this one's tasks ("already forgotten";
        # dask/distributed#4612)
        shared = client.scatter(setup, broadcast=True, hash=False)
        futures = {client.submit(function, shared, *key, pure=False): key for key in keys}
        for done, fut in enumerate(as_completed(futures), start=1):
            store(futures[fut], fut.result())
            if progress is not None:
                progress(done, len(futures))
    return cluster


def realisations_on_grid(prepare: Callable, simulate: Callable, config, cells: int, fields: Callable[[Any], dict],
                         error_row: Callable[[int, int, str, str], dict], *, what: str, scheduler: str | None = None,
                         workers: int | None = None, progress: Callable[[int, int], None] | None = None):
    """A Monte Carlo study's run: ``setup = prepare(config)`` made once, ``simulate(setup, cell, realisation)`` for
    every cell and ``config.realisations`` realisations on a Dask cluster (:func:`map_realisations`), each result's
    arrays stacked and its failures listed.

    Parameters
    ----------
    prepare : callable
        ``prepare(config) -> setup``, what every task shares.
    simulate : callable
        ``simulate(setup, cell, realisation) -> dict`` holding every name of ``fields`` and ``errors``
        ({estimator: message}).
    config : object
        The study's settings, with ``realisations``.
    cells : int
        Cells of the grid (noise levels, noise pairs).
    fields : callable
        ``fields(setup)`` -> {name: (shape of one result's array, fill value where a task gave none)}.
    error_row : callable
        ``error_row(cell, realisation, estimator, message) -> dict``: one failure as the study's JSON lists it, its
        sort keys first and the message last.
    what : str
        The command, for the message when Dask is missing.
    scheduler, workers, progress :
        As :func:`map_realisations`.

    Returns
    -------
    setup : object
    arrays : dict
        name -> (cells, realisations, *shape) array.
    errors : list of dict
        The failures, sorted by their rows' values before the message.
    cluster : str
        The cluster the tasks ran on.
    seconds : float
        The whole run's time, the setup's included [s].

    Raises
    ------
    ConfigError
        Dask missing (:func:`dynid.runtime.extras.require`), or from :func:`dask_client`.
    """
    require("distributed", "montecarlo", what)
    start = time.perf_counter()
    setup = prepare(config)
    grid = (cells, config.realisations)
    arrays = {name: np.full(grid + tuple(shape), fill) for name, (shape, fill) in fields(setup).items()}
    errors: list[dict] = []

    def store(key, out):
        for name, array in arrays.items():
            array[key] = out[name]
        errors.extend(error_row(*key, k, message) for k, message in out["errors"].items())

    cluster = map_realisations(simulate, setup, [(c, r) for c in range(grid[0]) for r in range(grid[1])], store,
                               scheduler, workers, what, progress)
    errors.sort(key=lambda row: tuple(row.values())[:-1])
    return setup, arrays, errors, cluster, time.perf_counter() - start
