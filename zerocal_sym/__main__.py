"""``python -m zerocal_sym`` and the ``zerocal`` console script: :func:`console`."""


def console() -> None:
    """Run the ``zerocal`` command line.

    A Ctrl-C or SIGTERM while the command line is imported (tens of
    milliseconds) is held, not raised inside an import: the CLI acts on it
    as soon as it is loaded (exit 130 or 143, one line, no traceback;
    :func:`zerocal_sym.cli.entry`).  Only this function does so: a worker
    process that imports the script (the ``spawn`` start method re-imports
    the main module) keeps the default handlers.  (A signal in the
    interpreter's own start, before any of this runs, ends the process as
    Python does.)
    """
    import _signal  # (the interpreter's own module, loaded already: ``signal`` would take a moment to import)

    held = []

    def hold(signum, frame):
        held.append(signum)

    for sig in (_signal.SIGINT, _signal.SIGTERM):
        try:
            _signal.signal(sig, hold)
        except (ValueError, OSError):  # not the main thread of the main interpreter
            pass
    from zerocal_sym.cli import entry

    entry(held)


if __name__ == "__main__":  # not when a spawned worker process re-imports the main module
    console()
