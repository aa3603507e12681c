"""Monte Carlo chunks on a Dask cluster: the client, its checks, the run (:func:`run_dask`).

:func:`zerocal_sym.identify.parallel.run_chunks` hands its chunks here when
given a ``scheduler`` (an address such as ``tcp://host:8786`` or a
``dask.distributed.Client``).  An address is checked before anything is
contacted (:func:`dask_client`), the scheduler is waited for at most
:func:`scheduler_timeout` seconds, and so are its workers; a client opened
here is closed after the run, also when it is interrupted.
"""
from __future__ import annotations

import math
import os

from zerocal_sym.errors import ZerocalError

#: seconds to wait for a Dask scheduler (override: ZEROCAL_SCHEDULER_TIMEOUT)
SCHEDULER_TIMEOUT_S = 10.0


def dask_client(scheduler):
    """``(client, owned)`` for a scheduler address or a Client (owned: we opened it and close it).

    Raises
    ------
    ZerocalError
        dask.distributed is not installed, the address is malformed (at once,
        nothing contacted), or the scheduler cannot be reached.
    """
    try:
        from dask.distributed import Client
    except ImportError:
        raise ZerocalError("--scheduler needs dask.distributed: pip install 'zerocal_sym[cluster]'") from None
    if isinstance(scheduler, Client):
        return scheduler, False
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise ZerocalError(f"--scheduler: expected an address like tcp://host:8786, got {scheduler!r}")
    _check_address(scheduler)
    timeout = scheduler_timeout()
    # Built in two steps to hold the client even when its constructor fails: one left half-open is closed
    # now (milliseconds), not by its __del__ at interpreter exit, which waits 20 s for an event loop that
    # has stopped and prints a TimeoutError traceback.
    client = Client.__new__(Client)
    try:
        client.__init__(scheduler, timeout=timeout, set_as_default=False)
    except BaseException as exc:
        _close_quietly(client)
        if not isinstance(exc, Exception):  # KeyboardInterrupt
            raise
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if isinstance(exc, (OSError, TimeoutError)):
            raise ZerocalError(f"cannot reach the Dask scheduler at {scheduler} within {timeout:g} s: "
                               f"{msg}") from None
        raise ZerocalError(f"cannot connect to the Dask scheduler at {scheduler}: {msg}") from None
    return client, True


def scheduler_timeout() -> float:
    """Seconds to wait for a scheduler: ``$ZEROCAL_SCHEDULER_TIMEOUT`` (a positive number) or
    :data:`SCHEDULER_TIMEOUT_S`."""
    text = os.environ.get("ZEROCAL_SCHEDULER_TIMEOUT")
    if text is None:
        return SCHEDULER_TIMEOUT_S
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise ZerocalError(f"ZEROCAL_SCHEDULER_TIMEOUT={text!r}: expected a positive number of seconds "
                           f"(default {SCHEDULER_TIMEOUT_S:g})")
    return value


def _require_workers(client, timeout: float) -> None:
    """A scheduler without workers would take the chunks and never run them: wait ``timeout`` s for one,
    then say so."""
    try:
        if client.scheduler_info().get("workers"):
            return
        client.wait_for_workers(1, timeout=timeout)
    except TimeoutError:
        raise ZerocalError(f"the Dask scheduler at {describe_scheduler(client)} has no workers (none joined "
                           f"within {timeout:g} s): start some (dask worker ADDRESS) or use --workers N "
                           "on this machine") from None


def _check_address(address: str) -> None:
    """A malformed scheduler address is an error before anything is contacted (no timeout to wait for)."""
    from distributed.comm.addressing import parse_address
    from distributed.comm.registry import get_backend

    expected = "expected an address like tcp://host:8786"
    scheme, loc = parse_address(address)
    try:
        backend = get_backend(scheme)
    except ValueError:
        raise ZerocalError(f"--scheduler {address}: unknown address scheme {scheme + '://'!r} "
                           f"({expected})") from None
    if scheme == "inproc":  # a scheduler in this process (LocalCluster(processes=False)): no host or port
        return
    try:
        host, port = backend.get_address_host_port(loc)
    except NotImplementedError:  # a scheme without host and port
        return
    except ValueError as exc:
        why = str(exc).splitlines()[0] if str(exc) else "invalid address"
        if "missing port" in why:
            why = "no port number"
        elif "invalid literal for int" in why:
            why = "the port is not a number"
        raise ZerocalError(f"--scheduler {address}: {why} ({expected})") from None
    if not host:
        raise ZerocalError(f"--scheduler {address}: no host ({expected})")
    if not 0 < int(port) < 65536:
        raise ZerocalError(f"--scheduler {address}: port {port} is out of range 1..65535 ({expected})")


def _close_quietly(client) -> None:
    try:
        client.close(timeout=2)
    except Exception:  # noqa: BLE001 - it never connected: nothing to release that matters
        pass


def describe_scheduler(scheduler):
    """The address of a scheduler (a string as given, a Client's scheduler address), or None."""
    if scheduler is None or isinstance(scheduler, str):
        return scheduler
    try:
        return str(scheduler.scheduler.address)
    except AttributeError:
        return str(scheduler)


def run_dask(fn, tasks, scheduler, finished):
    from dask.distributed import as_completed

    client, owned = dask_client(scheduler)
    futs = []
    try:
        _require_workers(client, scheduler_timeout())
        futs = [client.submit(fn, t, pure=False) for t in tasks]
        index = {f.key: i for i, f in enumerate(futs)}
        for f in as_completed(futs, loop=client.loop):  # our client: never the default one
            finished(index[f.key], f.result())
    except BaseException:
        try:
            client.cancel(futs)
        except Exception:  # noqa: BLE001 - the cluster may be gone already
            pass
        raise
    finally:
        if owned:
            client.close()
