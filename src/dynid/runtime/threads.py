"""Thread pools, set explicitly: small and medium linear algebra runs fastest on one BLAS thread on a
small machine, and a BLAS library may sum in another order with another number of threads, so results
would depend on the machine. dynid's entry points therefore run with one BLAS thread (threadpoolctl) and
use the cores for independent work instead (estimators side by side, Dask tasks). The compiled regressor
(numba) computes every sample on its own, so its thread count never changes a result.
"""

from __future__ import annotations

import functools
import os


def single_blas_thread():
    """Context manager: BLAS/LAPACK (OpenBLAS, MKL, …) limited to one thread inside it.

    Returns
    -------
    contextlib.AbstractContextManager
    """
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api="blas")


def with_single_blas_thread(func):
    """Decorator: a function runs under :func:`single_blas_thread` (results independent of the BLAS thread count).

    Parameters
    ----------
    func : callable

    Returns
    -------
    callable
    """

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with single_blas_thread():
            return func(*args, **kwargs)

    return wrapper


ONE_CORE_ENV = "DYNID_ONE_CORE"
"""Set (to any value) in a process that shares the machine's cores with its siblings (the workers of the local Dask
cluster, :func:`dynid.runtime.cluster.dask_client`): :func:`cores` is then 1, so the process starts no thread pools."""


def cores() -> int:
    """Cores this process may use: its CPU affinity, 1 where :data:`ONE_CORE_ENV` is set.

    Returns
    -------
    int
    """
    if os.environ.get(ONE_CORE_ENV):
        return 1
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1
