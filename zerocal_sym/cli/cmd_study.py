"""A Monte Carlo study: robots x designs x noise levels x truths x trials, chunked and resumable.

The spec (TOML; format in ``docs/montecarlo.md`` and
:mod:`zerocal_sym.cli.study_spec`) crosses robot files, measurement designs
(a scheme and n, or a pose file), noise levels (paper, scale-only,
servo-only, or factors of the paper's noise) and true source errors (tables
of name = value, deg for angles, mm otherwise).  Every cell runs ``trials``
one-shot Ipopt identifications in chunks; each chunk is written atomically to
``OUT/<cell-id>/chunk-<k>.npz``.  A rerun skips the chunks on disk (it says
how many), so an interrupted study resumes.  At the end the summary (per cell
and parameter: bias, RMS, CRLB, RMS/CRLB, 5 % / median / 95 % of the errors)
is printed and written to ``OUT/summary.json`` (a run with work to do first
removes the old one); ``--summary DIR`` prints it from the chunk files without
running anything.  A damaged chunk file or another cell's, and a directory
that holds another study, are refused before any work (one line naming it;
delete a refused chunk file to have it recomputed).

Examples:

    zerocal study examples/study.toml --out runs/study
    zerocal study examples/study.toml --out runs/study --workers 2
    zerocal study examples/study.toml --out runs/study --scheduler tcp://host:8786
    zerocal study examples/study.toml --summary runs/study --json
"""
NAME = "study"
HELP = "a Monte Carlo study over robots, designs, noise levels and truths (chunked, resumable)"
#: the files ``--out DIR`` writes into DIR (cli/study.py, cli/study_chunks.py: chunk_path, _cell_json)
FILES = ("summary.json", "*/cell.json", "*/chunk-*.npz")


def _hide_robot(p):
    """Take the shared ``--robot`` out of study's help (a study's robots are in its spec).

    The option stays accepted, hidden, so that giving it is the one-line error
    that says where the robots go (``_checks._study``).  The action is the
    parent parser's, shared by every command: study gets a hidden copy.
    """
    import argparse
    import copy

    for a in list(p._actions):
        if "--robot" in a.option_strings:
            hidden = copy.copy(a)
            hidden.help = argparse.SUPPRESS
            p._actions[p._actions.index(a)] = hidden
            for g in p._action_groups:
                if a in g._group_actions:
                    g._group_actions[g._group_actions.index(a)] = hidden
            for s in a.option_strings:
                p._option_string_actions[s] = hidden


def add_arguments(p):
    from zerocal_sym.cli import _parallel

    from zerocal_sym.cli._paths import InputDir, InputFile, OutputDir

    _hide_robot(p)
    p.add_argument("spec", metavar="SPEC.toml", type=InputFile("the study spec"), help="the study spec")
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--out", metavar="DIR", type=OutputDir(FILES), help="run the study into DIR (resumes what is there)")
    g.add_argument("--summary", metavar="DIR", type=InputDir("the study directory"),
                   help="only summarise the chunks in DIR")
    _parallel.add_arguments(p, "the identifications")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no account of the chunks")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    from zerocal_sym.cli._common import add_revisits_argument

    add_revisits_argument(p, "a pose file of the spec")


class _LineEnd:
    """stderr, remembering whether the last text written to it ended its line.

    A Ctrl-C inside a write (the account of the chunks, a progress line) may
    cut it before its newline: the run ends that line before "interrupted".
    """

    def __init__(self, stream):
        self.stream, self.open = stream, False

    def write(self, text):
        if text:
            self.open = True  # until the write is through
        n = self.stream.write(text)
        if text:
            self.open = not text.endswith("\n")
        return n

    def end_line(self):
        if self.open:
            self.stream.write("\n")
            self.stream.flush()
            self.open = False

    def __getattr__(self, name):
        return getattr(self.stream, name)


def run(args):
    from pathlib import Path

    from zerocal_sym.cli import _parallel
    from zerocal_sym.errors import ZerocalError
    from zerocal_sym.cli import study as st
    from zerocal_sym.cli.study_spec import load_spec
    from zerocal_sym.identify.progress import Progress
    from zerocal_sym.io.files import to_json

    from zerocal_sym.model.compiled import mode

    if getattr(args, "robot", None):
        raise ZerocalError("--robot: a study's robots are listed in its spec (robots = [...])")
    if args.summary is not None:
        given = getattr(args, "_given", None)
        bad = [o for o, d, default in (("--workers", "workers", 1), ("--scheduler", "scheduler", None))
               if (d in given if given is not None else getattr(args, d) != default)]
        if bad:
            raise ZerocalError(f"{', '.join(bad)}: where the study runs (--out DIR); --summary only reads the chunk "
                               "files on disk")
    mode()  # ZEROCAL_COMPILE: a bogus value is a user error before anything is read or written
    spec = load_spec(args.spec, getattr(args, "allow_revisits", False))
    if args.out is not None:  # the files the spec names are inputs too (the spec itself: cli/_checks.py)
        from zerocal_sym.io.files import check_outputs

        check_outputs([("--out", args.out, FILES)], spec.inputs)
    if args.summary is not None:
        if Path(args.summary).is_file():
            raise ZerocalError("is a file" + (" (the spec?)" if Path(args.summary).suffix == ".toml" else "")
                               + ": --summary expects the study's output directory (the --out DIR of a run)",
                               where=args.summary)
        if not Path(args.summary).is_dir():
            raise ZerocalError("no such study directory (--summary expects the --out DIR of a run)",
                               where=args.summary)
        summary = st.summarize(spec, args.summary)
    else:
        import sys

        err = _LineEnd(sys.stderr)
        ex = _parallel.execution(args)
        bars = []

        def make_progress(total):
            bars.append(Progress(total, "study", stream=err, enabled=not args.quiet and total > 0))
            return bars[-1]

        def log(text):
            err.write(text + "\n")  # one write: the line and its end
            err.flush()

        try:
            summary = st.run_study(spec, args.out, log=None if args.quiet else log, make_progress=make_progress,
                                   **ex)
        finally:
            for b in bars:
                b.close()
            err.end_line()  # interrupted inside a line: "zerocal study: interrupted" on its own
            _parallel.close(ex)
    from zerocal_sym.cli._interrupt import outputs_written

    outputs_written()  # from here on it only reports: a Ctrl-C or SIGTERM does not change its status
    print(to_json(summary) if args.json else st.format_summary(summary))
    return 0
