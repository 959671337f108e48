"""experiments.common.worker_pool: processes capped at the CPUs, numba threads shared out (issue 29)."""

from bionav.experiments.common import worker_pool
from bionav.machine import usable_cpus


def _numba_threads(_):
    import os

    import numba

    return os.getpid(), int(numba.config.NUMBA_NUM_THREADS)


def test_more_workers_than_cpus_get_one_process_per_cpu_and_their_share_of_threads():
    cpus = usable_cpus()
    with worker_pool(cpus + 3) as pool:
        assert pool._processes == cpus
        got = pool.map(_numba_threads, range(4 * cpus), chunksize=1)
    assert {threads for _, threads in got} == {1}  # cpus // cpus
    assert len({pid for pid, _ in got}) <= cpus


def test_fewer_workers_share_the_cpus_between_them():
    cpus = usable_cpus()
    with worker_pool(1) as pool:
        assert pool._processes == 1
        assert pool.apply(_numba_threads, (0,))[1] == cpus
