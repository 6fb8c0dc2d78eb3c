"""`tradeoff` of a scene measured twice, in one run: here on one thread, and on a Dask
LocalCluster of N worker processes (one thread each); the rows compared field by field
(host times aside), and both wall times printed.

    python3 crates/python/examples/dask_tradeoff.py pot 2
"""

import sys
import time

from dask.distributed import Client, LocalCluster

import cwisim
from cwisim import sweep


def main() -> None:
    scene = sys.argv[1] if len(sys.argv) > 1 else "pot"
    workers = int(sys.argv[2]) if len(sys.argv) > 2 else 2
    start = time.perf_counter()
    local = cwisim.tradeoff(scene, repeat=1)
    local_s = time.perf_counter() - start
    with LocalCluster(
        n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, Client(cluster) as client:
        start = time.perf_counter()
        distributed = cwisim.tradeoff(scene, repeat=1, client=client)
        dask_s = time.perf_counter() - start
    differences = sweep.compare(local, distributed)
    print(f"{scene}: {len(local)} rows; one thread {local_s:.2f} s; "
          f"Dask, {workers} workers {dask_s:.2f} s ({local_s / dask_s:.2f}×); "
          f"rows differing (host times aside): {len(differences)}")
    sys.exit(1 if differences else 0)


if __name__ == "__main__":
    main()
