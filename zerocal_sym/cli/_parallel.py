"""``--workers N`` / ``--scheduler ADDRESS``: where a Monte Carlo runs (compare, design --verify, study)."""
from __future__ import annotations


def add_arguments(p, what: str = "the Monte Carlo") -> None:
    p.add_argument("--workers", type=int, default=1, metavar="N",
                   help=f"local processes for {what} (default 1: this process); results do not depend on N")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="run on a Dask cluster instead (tcp://host:8786; needs pip install 'zerocal_sym[cluster]')")


def execution(args) -> dict:
    """``{"workers": N, "scheduler": ADDRESS}`` from the options, checked (one-line errors, exit 2).

    A scheduler is contacted here, before any work or output: an unreachable
    one or a missing dask is an error now.  The returned scheduler is a
    connected ``dask.distributed.Client`` (close it with :func:`close`).
    """
    from zerocal_sym.identify.dask_cluster import dask_client
    from zerocal_sym.identify.parallel import check_execution

    workers = check_execution(args.workers, args.scheduler)
    if args.scheduler is None:
        return {"workers": workers, "scheduler": None}
    client, _ = dask_client(args.scheduler)
    return {"workers": 1, "scheduler": client}


def close(ex: dict) -> None:
    client = ex.get("scheduler")
    if client is not None and not isinstance(client, str):
        client.close()
