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

SIGTERM (``kill PID``, a job scheduler's stop) is handled the same way: the
command stops, cleans up (worker processes, temporary files and directories)
and exits with :data:`EXIT_STATUS` ``[SIGTERM]`` = 143 instead of 130
(:func:`interrupt_status`).

Once the command has written its outputs -- it called :func:`outputs_written`,
or its ``run`` returned (:meth:`_Redeliver.call`) -- a Ctrl-C or SIGTERM no
longer stops it: its outputs and exit status stand (it only reports).
"""
from __future__ import annotations

import _thread
import contextlib
import os
import signal
import sys
import threading
import time


#: the signals that stop a command, and the exit status of each (128 + the signal's number)
EXIT_STATUS = {signal.SIGINT: 130, signal.SIGTERM: 143}
#: what the command says when it stops on each
WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}

_received: set = set()  # the signals of the current command (from its start)
_active = None          # the _Redeliver of the command running (installed())


def note(signum) -> None:
    """Record that ``signum`` arrived (the exit status says which: :func:`interrupt_status`)."""
    _received.add(signum)


def reset() -> None:
    """Forget the signals of an earlier command (a new one starts)."""
    _received.clear()


def interrupt_status() -> tuple:
    """``(exit status, word)`` of a stopped command: SIGTERM's (143, "terminated") if one arrived, else
    Ctrl-C's (130, "interrupted")."""
    sig = signal.SIGTERM if signal.SIGTERM in _received else signal.SIGINT
    return EXIT_STATUS[sig], WORDS[sig]


def startup_handler(signum, frame):
    """The handler while the CLI starts (parsing, imports): note the signal and stop (KeyboardInterrupt)."""
    note(signum)
    raise KeyboardInterrupt


def install_startup_handlers() -> None:
    """SIGINT and SIGTERM raise KeyboardInterrupt (noted) until :func:`installed` takes over."""
    for sig in EXIT_STATUS:
        signal.signal(sig, startup_handler)


def ignore_signals() -> None:
    """The command is over (done, or stopped and reported): a late Ctrl-C or SIGTERM does not change its status."""
    for sig in EXIT_STATUS:
        try:
            signal.signal(sig, signal.SIG_IGN)
        except (ValueError, OSError):  # not the main thread
            pass


def outputs_written() -> None:
    """Called by a command once its outputs are in place: from here on it is not stopped by a signal."""
    if _active is not None:
        _active.done = True


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
        self.done = False  # the command has written its outputs or returned: signals no longer stop it
        self.signum = signal.SIGINT  # the signal to re-trip with (the last one received)
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
                    _thread.interrupt_main(self.signum)  # the main thread runs the handler at its next check
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
        note(signum)
        self.signum = signum
        if self.done or is_interrupt(sys.exc_info()[1]):  # finished, or already on its way up: let it end
            return
        self._kick()  # pending again soon, in case C code swallows this one
        if frame is not None and frame.f_code is _CALL_CODE:
            return  # in call() itself, just before or just after the command: decided at the re-trip
        raise KeyboardInterrupt

    def call(self, fn, *args):
        """``fn(*args)`` (the command's ``run``); once it has returned, a signal no longer stops anything."""
        try:
            return fn(*args)
        finally:
            self.done = True

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


_CALL_CODE = _Redeliver.call.__code__


class _Plain:
    """What :func:`installed` yields where it cannot install a handler: :meth:`call` only."""

    done = False

    def call(self, fn, *args):
        return fn(*args)


@contextlib.contextmanager
def installed():
    """The handlers of SIGINT and SIGTERM for the ``with`` block (main thread only; elsewhere a no-op).

    Yields the object whose ``call(run, args)`` runs the command (:meth:`_Redeliver.call`).
    """
    global _active
    if threading.current_thread() is not threading.main_thread():
        yield _Plain()
        return
    redeliver = _Redeliver()
    previous = {}
    try:
        for sig in EXIT_STATUS:
            previous[sig] = signal.signal(sig, redeliver.handler)
    except (ValueError, OSError):  # no signals here (an embedded interpreter)
        _restore(previous)
        redeliver.close()
        yield _Plain()
        return
    _active = redeliver
    try:
        yield redeliver
    finally:
        _active = None
        for sig in previous:
            signal.signal(sig, _noop)  # a re-trip still pending is taken here, not by the caller
        redeliver.close()
        _noop()
        _restore(previous)


def _restore(previous: dict) -> None:
    for sig, handler in previous.items():
        if handler is not None:  # (None: a handler not set from Python; it cannot be put back)
            signal.signal(sig, handler)
