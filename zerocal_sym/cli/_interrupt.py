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
import os
import signal
import sys
import threading
import time


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
    """Keeps a Ctrl-C pending until Python code has it (a helper thread re-trips SIGINT after each raise).

    The handler only writes a byte to a pipe the helper thread reads (it
    takes no lock): two SIGINTs microseconds apart (GNU ``timeout`` signals
    the process and then its group) run the handler again inside the first
    run, and a lock taken there (``threading.Event.set``, as before) was held
    by the interrupted run itself: the command hung for good.
    """

    #: how long after a raise the signal is made pending again (s): time for C code to return
    DELAY = 0.05

    def __init__(self):
        self.lock = threading.Lock()
        self.closed = False
        self.ended = None  # why the thread ended: "closed" (woken by close()) or "eof" (the pipe closed on it)
        self._r, self._w = os.pipe()
        self.thread = threading.Thread(target=self._run, name="zerocal-ctrl-c", daemon=True)
        self.thread.start()

    def _run(self):
        try:
            while True:
                try:
                    data = os.read(self._r, 4096)  # a burst of Ctrl-C: one re-trip
                except OSError:
                    data = b""
                if not data:
                    self.ended = "eof"
                    return
                if self.closed:
                    self.ended = "closed"
                    return
                time.sleep(self.DELAY)
                with self.lock:
                    if self.closed:
                        return
                    _thread.interrupt_main()  # the main thread runs the handler at its next check
        finally:
            os.close(self._r)

    def _wake(self):
        try:
            os.write(self._w, b"!")
        except OSError:  # closed: nothing to wake
            pass

    def _kick(self):
        if not self.closed:  # (set before the pipe is closed; the handler and close() share the main thread)
            self._wake()

    def handler(self, signum, frame):
        if is_interrupt(sys.exc_info()[1]):  # already on its way up: let the cleanup run
            return
        self._kick()  # pending again soon, in case C code swallows this one
        raise KeyboardInterrupt

    def close(self):
        with self.lock:
            self.closed = True
        self._wake()  # the thread sees closed and ends
        self.thread.join(1.0)
        try:
            os.close(self._w)
        except OSError:
            pass


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
        signal.signal(signal.SIGINT, _noop)  # a re-trip still pending is taken here, not by the caller
        redeliver.close()
        _noop()
        signal.signal(signal.SIGINT, previous)
