"""Sweeps on a Dask cluster: each group of a ``tradeoff`` plan (the settings that share
one stream) is a Dask task, measured on a worker by the same native code as the local
sweep, and the rows gathered in the grid's order. Dask schedules; cwisim has no
scheduler of its own. Any ``dask.distributed.Client`` serves: a ``LocalCluster`` on one
machine, or a cluster on Kubernetes or Slurm (dask-jobqueue) beyond it, provided the
workers have the ``cwisim`` package (and the scene file, at the same path).
"""

from __future__ import annotations

import json
from typing import Any, Dict, List, Tuple

from . import _native

#: Plans made in this (worker) process, by their arguments: a worker that measures
#: several groups of one sweep makes its plan, and each reference image, once.
_PLANS: Dict[str, Any] = {}


def _plan(args: Dict[str, Any]):
    key = json.dumps(args, sort_keys=True)
    plan = _PLANS.get(key)
    if plan is None:
        plan = _PLANS[key] = _native.TradeoffPlan(**args)
    return plan


def measure_group(args: Dict[str, Any], g: int, repeat: int) -> List[Dict[str, Any]]:
    """The rows of group ``g`` of the plan of ``args`` (a Dask task)."""
    from . import rows_of  # noqa: PLC0415

    return rows_of(_plan(args).measure(g, repeat))


def tradeoff_on(
    client: Any, plans: List[Dict[str, Any]], repeat: int
) -> List[List[Dict[str, Any]]]:
    """The sweeps of ``plans`` (one per scene) on ``client``'s cluster: one task per group
    of every plan, all submitted at once, gathered in order; each plan's rows, unmarked."""
    tasks = [
        (k, g)
        for k, args in enumerate(plans)
        for g in range(_native.TradeoffPlan(**args).groups())
    ]
    futures = client.map(
        measure_group,
        [plans[k] for k, _ in tasks],
        [g for _, g in tasks],
        [repeat] * len(tasks),
        pure=False,
    )
    out: List[List[Dict[str, Any]]] = [[] for _ in plans]
    for (k, _), group in zip(tasks, client.gather(futures)):
        out[k].extend(group)
    return out


def compare(local: List[Dict[str, Any]], distributed: List[Dict[str, Any]]) -> List[Tuple[int, str]]:
    """Where two sweeps' rows differ, as (row, field), host times aside (they are the
    machine's, not the sweep's)."""
    out = []
    if len(local) != len(distributed):
        out.append((-1, f"{len(local)} rows against {len(distributed)}"))
    for k, (a, b) in enumerate(zip(local, distributed)):
        for field in a:
            if field != "host_ms" and a[field] != b.get(field):
                out.append((k, field))
    return out
