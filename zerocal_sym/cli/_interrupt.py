"""Ctrl-C that a solver cannot swallow.

CasADi checks for Ctrl-C inside its solvers (Ipopt's intermediate callback
calls ``PyErr_CheckSignals``) and, when it sees one, may stop the solve and
return normally: the ``KeyboardInterrupt`` is logged as a warning and
cleared, the identification "did not converge", and a Monte Carlo goes on
with the next trial (``zerocal compare`` ran on after SIGINT).

:func:`installed` puts a SIGINT handler in place for the duration of a
command.  It raises ``KeyboardInterrupt`` as Python's own does, and until the
interrupt has reached Python code a helper thread makes the signal pending
again shortly after each raise (``_thread.interrupt_main``): if C code
swallowed the exception, the handler runs again at the next check -- in the
end in the Python frame the solver returns to, where the exception
propagates as usual.  Once the interrupt is
being handled (the handler runs while a ``KeyboardInterrupt``, or an error
made of one, is the exception being handled: a ``finally`` or ``except``
cleaning up), it does nothing more, so cleanup code runs undisturbed.
"""
from __future__ import annotations

import _thread
import contextlib
import signal
import sys
import threading


def is_interrupt(exc) -> bool:
    """Whether ``exc`` is Ctrl-C: a KeyboardInterrupt in its cause/context chain, or CasADi's
    ``RuntimeError("KeyboardInterrupt")``, or an error C code made of one (``SystemError ... exception set``)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt) or (isinstance(exc, RuntimeError)
                                                  and str(exc).strip() == "KeyboardInterrupt"):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


class _Redeliver:
    """Keeps a Ctrl-C pending until Python code has it (a helper thread re-trips SIGINT after each raise)."""

    #: how long after a raise the signal is made pending again (s): time for C code to return
    DELAY = 0.05

    def __init__(self):
        self.lock = threading.Lock()
        self.kick = threading.Event()
        self.closed = False
        self.thread = threading.Thread(target=self._run, name="zerocal-ctrl-c", daemon=True)
        self.thread.start()

    def _run(self):
        while True:
            self.kick.wait()
            self.kick.clear()
            if self.closed:
                return
            threading.Event().wait(self.DELAY)
            with self.lock:
                if self.closed:
                    return
                _thread.interrupt_main()  # the main thread runs the handler at its next check

    def handler(self, signum, frame):
        if is_interrupt(sys.exc_info()[1]):  # already on its way up: let the cleanup run
            return
        self.kick.set()  # pending again soon, in case C code swallows this one
        raise KeyboardInterrupt

    def close(self):
        with self.lock:
            self.closed = True
        self.kick.set()


def _noop(*args):
    return None


@contextlib.contextmanager
def installed():
    """The handler for the ``with`` block (main thread only; elsewhere a no-op)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    redeliver = _Redeliver()
    try:
        previous = signal.signal(signal.SIGINT, redeliver.handler)
    except (ValueError, OSError):  # no signals here (an embedded interpreter)
        redeliver.close()
        yield
        return
    try:
        yield
    finally:
        redeliver.close()
        signal.signal(signal.SIGINT, _noop)  # a re-trip still pending is taken here, not by the caller
        _noop()
        signal.signal(signal.SIGINT, previous)
