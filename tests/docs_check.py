"""The docs checker: every command a page shows is run, and every number it shows is compared with the output.

The convention (README.md, "Development", "Docs that run") in short:

* A fenced block tagged ``console`` holds commands (lines starting with ``$ ``, continued by a trailing ``\\``)
  each followed by what it prints on stdout.  The output must match line by line: a line ``...`` skips any
  number of lines, ``...`` inside a line any text, a run of blanks any run of blanks, and a number matches when
  the printed one equals it to the digits shown (``0.4910`` admits [0.49095, 0.49105]), or, right before
  ``...``, when the printed one starts with its digits (``-1.9540068...``).  A last line
  ``[exit N]`` says the command exits with status N (else 0 is required).
* A fenced block tagged ``bash`` (or ``sh``) is run line by line; each command must exit 0, its output is not
  compared (the block shows none).
* ``<!-- check-block: ... -->`` on the line before a fence: ``slow`` (run in a test of its own, marked slow, in a
  fresh directory: the block must not need files an earlier block wrote), ``not run: REASON`` (its commands are
  not run, for the reason given: they need your own files, a cluster, or another test runs them),
  ``file NAME`` (the block's text is written to NAME before the page's commands run).
* A number in prose or a table is tied to the command that prints it by a comment after it::

      <!-- check: zerocal design --scheme paper --json
      kappa_1: 475.342
      crlb_zero_offsets_deg: 0.522 0.522
      -->

  ``<!-- check slow: ...`` for a command too long for the fast tests (run once per session in a fresh directory,
  whichever pages show it; so is each line of a slow bash block).  When the command prints JSON (from its
  first line starting with ``{``), each line is ``PATH: VALUES``: PATH a dotted key path (``a.b[0]``, ``[*]`` for
  every element of a list, ``[0:3]`` some, ``.*`` every value of an object), VALUES numbers compared at their
  digits with the values there (flattened, in order), ``LO..HI`` (the smallest and the largest value, at the
  digits shown), ``<X`` or ``<=X`` (every value), or a quoted string.  Otherwise each line is a pattern like a
  console output line, found in the output in order (a part of a line, each on a later line than the one
  before); ``{<X}`` / ``{<=X}`` in a pattern is a number
  that must be below X.  Every number a check compares must also appear in the page's text of the same section
  (from the heading before it to the comment), so that the prose and the check cannot drift apart.

Commands run with bash in a scratch directory holding a copy of the repository's ``examples/`` and
``benchmarks/``, ``zerocal`` and
``python`` the test interpreter's; a page's commands (blocks and checks, not the slow ones) run in order in one
directory, so a command sees the files the ones before it wrote.  A check whose command ran before on the page
reuses that output; a check whose command another page shows too, or a slow item runs, takes the session's one run
of it in a fresh directory (so it must need nothing the page wrote before).
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: the folders a page's commands find in their scratch directory (its example files, the benchmark scripts it runs)
COPIED = ("examples", "benchmarks")
#: the pages the checker reads
PAGES = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))

#: a number as a page prints it: not the tail of a word (``theta1``, ``P1``) nor the head of one (``2eaac3``)
NUMBER = r"(?<![\w.])(?<![\w.][-+])[-+]?(?:\d+(?:\.\d+)?|\.\d+)(?:[eE][-+]?\d+)?(?![\w]|\.\d)"
#: the same inside an output line: a captured number, signed or not, any digits
ANY_NUMBER = r"([-+]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][-+]?\d+)?)"
BOUND = r"\{(<=?)\s*(" + NUMBER[len(r"(?<![\w.])(?<![\w.][-+])"):] + r")\}"
MINUS = "\u2212"
FENCE = re.compile(r"^( {0,3})(```+|~~~+)\s*([\w+-]*)\s*$")
CHECK_OPEN = re.compile(r"^<!--\s*check(\s+slow)?:\s*(.*)$")
BLOCK_DIRECTIVE = re.compile(r"^\s*<!--\s*check-block:\s*(.*?)\s*-->\s*$")
RUN_LANGS = {"console", "bash", "sh", "shell"}


# ----------------------------------------------------------------------------------------------- the page
def _rel(path: Path) -> str:
    return path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else str(path)


@dataclass
class Command:
    text: str
    line: int
    expected: list[str] | None = None  # None: output not compared
    exit_status: int = 0


@dataclass
class Item:
    """A block of commands or a check; ``kind`` is ``"block"`` or ``"check"``."""
    page: Path
    line: int
    kind: str
    commands: list[Command]
    slow: bool = False
    expectations: list[str] = field(default_factory=list)  # a check's lines
    region: str = ""  # a check's section text (for the quoting rule)

    @property
    def where(self) -> str:
        return f"{_rel(self.page)}:{self.line}"


@dataclass
class Page:
    path: Path
    items: list[Item]
    files: dict[str, str]  # ``file NAME`` blocks
    fenced: list[tuple[int, str, str, str | None]]  # every fence: (line, lang, text, not-run reason)


def parse_page(path: Path) -> Page:
    lines = path.read_text(encoding="utf-8").splitlines()
    items, files, fenced = [], {}, []
    section_start, i, directive = 0, 0, None
    while i < len(lines):
        ln = lines[i]
        m = FENCE.match(ln)
        if m:
            indent, fence, lang, start = len(m.group(1)), m.group(2), m.group(3).lower(), i + 1
            j = start
            while j < len(lines) and not lines[j].strip().startswith(fence[:3]):
                j += 1
            body = [ln[indent:] if ln[:indent].isspace() else ln for ln in lines[start:j]]
            words = (directive or "").split(None, 1)
            reason = directive.split(":", 1)[1].strip() if directive and directive.startswith("not run") else None
            fenced.append((start, lang, "\n".join(body), reason))
            if directive and words[0] == "file":
                files[words[1].strip()] = "\n".join(body) + "\n"
            elif lang in RUN_LANGS and reason is None:
                cmds = _console_commands(body, start, path) if lang == "console" else _script_commands(body, start)
                if cmds:
                    items.append(Item(path, start, "block", cmds, slow=directive == "slow"))
            elif directive and reason is None:
                raise ValueError(f"{_rel(path)}:{start}: check-block {directive!r} on a {lang or 'plain'} "
                                 "block (slow: a console or bash block; not run: REASON; file NAME)")
            directive, i = None, j + 1
            continue
        d = BLOCK_DIRECTIVE.match(ln)
        if d:
            directive = d.group(1)
            if not re.fullmatch(r"slow|not run:\s*\S.*|file\s+\S+", directive):
                raise ValueError(f"{_rel(path)}:{i + 1}: unknown check-block directive {directive!r}")
            i += 1
            continue
        c = CHECK_OPEN.match(ln)
        if c:
            start, body, j = i + 1, [], i + 1
            first = c.group(2)
            if first.rstrip().endswith("-->"):
                raise ValueError(f"{_rel(path)}:{start}: a check states what it compares on the lines "
                                 "after its command, and ends with --> on a line of its own")
            while j < len(lines) and lines[j].strip() != "-->":
                if "-->" in lines[j]:
                    raise ValueError(f"{_rel(path)}:{j + 1}: a check comment ends with --> on a line of its own")
                body.append(lines[j])
                j += 1
            if j == len(lines):
                raise ValueError(f"{_rel(path)}:{start}: check comment without its closing -->")
            exit_status, body = _exit_line([b for b in body if b.strip()])
            region = _strip_comments("\n".join(lines[section_start:i]))
            items.append(Item(path, start, "check", [Command(first.strip(), start, None, exit_status)],
                              slow=bool(c.group(1)), expectations=body, region=region))
            i = j + 1
            continue
        if ln.startswith("#"):
            section_start = i
        directive = None if ln.strip() else directive
        i += 1
    return Page(path, items, files, fenced)


def _strip_comments(text: str) -> str:
    return re.sub(r"<!--.*?-->", "", text, flags=re.S)


def _exit_line(lines):
    if lines and re.fullmatch(r"\[exit (\d+)\]", lines[-1].strip()):
        return int(re.fullmatch(r"\[exit (\d+)\]", lines[-1].strip()).group(1)), lines[:-1]
    return 0, lines


def _join_continued(body, first_line):
    """``[(line number, command)]``: lines ending in ``\\`` joined to the next."""
    out, cur, at = [], None, None
    for k, ln in enumerate(body):
        if cur is None:
            cur, at = ln, first_line + k
        else:
            cur = cur[:-1] + " " + ln.strip()
        if not cur.rstrip().endswith("\\"):
            out.append((at, cur))
            cur = None
    if cur is not None:
        out.append((at, cur))
    return out


def _console_commands(body, first_line, path):
    cmds, k = [], 0
    while k < len(body):
        ln = body[k]
        if ln.startswith("$ "):
            text, at = ln[2:], first_line + k
            while text.rstrip().endswith("\\") and k + 1 < len(body):
                k += 1
                text = text.rstrip()[:-1] + " " + body[k].strip()
            cmds.append(Command(text, at + 1, []))
        elif cmds:
            cmds[-1].expected.append(ln)
        elif ln.strip():
            raise ValueError(f"{_rel(path)}:{first_line + k + 1}: a console block starts with a "
                             "'$ ' command line")
        k += 1
    for c in cmds:
        while c.expected and not c.expected[-1].strip():
            c.expected.pop()
        c.exit_status, c.expected = _exit_line(c.expected)
    return cmds


def _script_commands(body, first_line):
    return [Command(text, at + 1) for at, text in _join_continued(body, first_line)
            if text.strip() and not text.lstrip().startswith("#")]


#: ``zerocal SUBCOMMAND`` in a line of a fenced block, not a line of output such as ``zerocal identify: error: ...``
ZEROCAL_WORD = re.compile(r"(?:^|[\s;&|(])(?:\S*/)?zerocal\s+(?!\S*:(?:\s|$))[\w-]")


def zerocal_lines(page: Page):
    """Every zerocal command in a fenced block: ``[(line, text, not-run reason or None, run)]``.

    In a console block its ``$`` lines (the rest is output); elsewhere every line naming ``zerocal SUBCOMMAND``
    outside a ``#`` comment.
    """
    run_lines = {c.line for it in page.items if it.kind == "block" for c in it.commands}
    out = []
    for start, lang, text, reason in page.fenced:
        for k, ln in enumerate(text.splitlines()):
            if lang == "console" and not ln.startswith("$ "):
                continue
            m = ZEROCAL_WORD.search(ln)
            if m and "#" not in ln[:m.start() + 1] and not ln.lstrip().startswith(";"):
                at = start + k + 1
                out.append((at, ln.strip(), reason, lang in RUN_LANGS and reason is None and at in run_lines))
    return out


# ----------------------------------------------------------------------------------------------- comparing
def shown(text: str):
    """A number as printed, ``(value, half a unit of its last digit)``; the page's minus sign read as ``-``."""
    t = text.strip().replace(MINUS, "-")
    m = re.fullmatch(r"([+-]?)(\d*)(?:\.(\d*))?(?:[eE]([+-]?\d+))?", t)
    if not m or not (m.group(2) or m.group(3)):
        raise ValueError(f"not a number as a page prints it: {text!r}")
    return float(t), 0.5 * 10.0 ** (int(m.group(4) or 0) - len(m.group(3) or ""))


def at_digits(value: float, text: str) -> bool:
    """``value`` rounds to the number ``text`` shows (half a unit of its last digit, and a hair for the binary)."""
    want, half = shown(text)
    return math.isfinite(value) and abs(value - want) <= half * (1 + 1e-9) + 1e-15 * abs(want)


def _tokens(expected: str, bounds: bool):
    """An expected line as tokens: ``("any",)`` for ``...``, ``("text", regex)``, ``("num", op, text)``."""
    toks, pos = [], 0
    token = re.compile(r"(\.\.\.)|" + (BOUND + "|" if bounds else "") + "(" + NUMBER + ")")

    def text(t):
        if t:
            toks.append(("text", re.compile(r"\s+".join(re.escape(w) if w else "" for w in re.split(r"\s+", t)))))

    for m in token.finditer(expected):
        before = expected[pos:m.start()]
        text(before.rstrip() if m.group(1) else (before.lstrip() if toks and toks[-1][0] == "any" else before))
        if m.group(1):
            toks.append(("any",))
        elif bounds and m.group(2):
            toks.append(("num", m.group(2), m.group(3)))
        else:  # a number; right before ``...`` its digits go on: the printed number starts with them
            toks.append(("num", "..." if expected.startswith("...", m.end()) else "=", m.group(m.lastindex)))
        pos = m.end()
    text(expected[pos:].lstrip() if toks and toks[-1][0] == "any" else expected[pos:])
    return toks


_ACTUAL_NUMBER = re.compile(ANY_NUMBER + r"(?![\w]|\.\d)")


def _number_fails(got: str, op: str, want: str):
    if op == "...":
        return None if got.lstrip("+").startswith(want.lstrip("+")) else f"{got} where the page shows {want}..."
    v = float(got)
    if op == "=":
        return None if at_digits(v, want) else f"{got} where the page shows {want}"
    return None if (v < float(want) if op == "<" else v <= float(want)) else f"{got}, not {op} {want}"


def line_matches(expected: str, actual: str, search: bool = False, bounds: bool = False):
    """``(True, None)``, or ``(False, why)``: the text differs (``why`` None) or a number does (``why`` says which).

    A small backtracking matcher: ``...`` tries every length, a number must be a whole number of the output (not
    the tail of ``x59`` or of ``-0.5``) and pass its comparison, so ``nlls ... 59`` finds the 59 of a line.
    ``search``: the expected text may match a part of the line.
    """
    toks = _tokens(expected.replace(MINUS, "-").strip(), bounds)
    act = actual.strip()
    why = []

    def go(t, pos):
        if t == len(toks):
            return search or pos == len(act)
        tok = toks[t]
        if tok[0] == "any":
            return any(go(t + 1, p) for p in range(pos, len(act) + 1))
        if tok[0] == "text":
            m = tok[1].match(act, pos)
            return bool(m) and go(t + 1, m.end())
        # a whole number of the output: not the tail of x59 or -0.5 (unless the page's text before it took that
        # character: ``+-0.5``)
        glued = t == 0 or toks[t - 1][0] == "any"
        if glued and pos > 0 and (act[pos - 1].isalnum() or act[pos - 1] in "._+-"):
            return False
        m = _ACTUAL_NUMBER.match(act, pos)
        if not m:
            return False
        bad = _number_fails(m.group(1), tok[1], tok[2])
        if bad:
            why.append(bad)
            return False
        return go(t + 1, m.end())

    starts = range(len(act) + 1) if search else [0]
    if any(go(0, p) for p in starts):
        return True, None
    return False, (why[0] if why else None)


def match_output(expected: list[str], actual: str):
    """Compare a console block's expected lines with what the command printed: ``None`` or what differs."""
    act = [ln.rstrip() for ln in actual.rstrip("\n").splitlines()]
    while act and not act[-1].strip():
        act.pop()
    exp = list(expected)
    best = {"at": -1, "msg": None, "why": None}

    def go(e, a):
        if e == len(exp):
            return a == len(act)
        if exp[e].strip() == "...":
            return any(go(e + 1, k) for k in range(a, len(act) + 1))
        if a < len(act):
            ok, why = line_matches(exp[e], act[a])
            if ok:
                return go(e + 1, a + 1)
            if e > best["at"] or (e == best["at"] and why and not best["why"]):
                best.update(at=e, why=why, msg=(f"expected line {e + 1}: {exp[e].strip()!r}\n      printed: "
                                                f"{act[a].strip()!r}" + (f"\n      ({why})" if why else "")))
        elif e > best["at"]:
            best.update(at=e, why=None, msg=f"expected line {e + 1}: {exp[e].strip()!r}\n      but the output ended")
        return False

    if go(0, 0):
        return None
    if best["msg"] is None:
        return f"the command printed {len(act)} lines, more than the page shows (end the output with '...')"
    return best["msg"]


# ----------------------------------------------------------------------------------------------- checks
def _json_of(text: str):
    lines = text.splitlines()
    for k, ln in enumerate(lines):
        if ln.startswith("{"):
            try:
                return json.loads("\n".join(lines[k:]))
            except ValueError:
                return None
    return None


def json_values(data, path: str):
    """The values at a dotted path (``a.b[0]``; ``a[*].b`` every element of a list, ``a[0:3].b`` some, ``a.*.b``
    every value of an object), flattened to a list."""
    items = [data]
    for tok in re.findall(r"\[(\*|\d+|\d*:\d*)\]|([^.\[\]]+)", path):
        nxt = []
        for it in items:
            if tok[0] == "*" or tok[1] == "*":
                nxt += list(it.values()) if isinstance(it, dict) else list(it)
            elif ":" in tok[0]:
                a, b = (int(x) if x else None for x in tok[0].split(":"))
                nxt += list(it[a:b])
            elif tok[0]:
                nxt.append(it[int(tok[0])])
            else:
                nxt.append(it[tok[1]])
        items = nxt

    def flat(x):
        return [y for v in x for y in flat(v)] if isinstance(x, list) else [x]

    return flat(items)


def _value_words(spec: str):
    return [w for w in re.split(r"[,\s]+", spec.strip()) if w]


def check_json(data, line: str):
    """One ``PATH: VALUES`` line against the JSON: ``(None or what differs, [numbers it compares])``."""
    m = re.match(r"\s*(\S+?):\s+(\S.*)$", line)  # the first colon before a blank (a slice's is not)
    if not m:
        return f"not a 'PATH: VALUES' line: {line!r}", []
    path, spec = m.groups()
    try:
        vals = json_values(data, path.strip())
    except (KeyError, IndexError, TypeError) as exc:
        return f"{path.strip()}: no such value in the output ({exc!r})", []
    spec = spec.strip().replace(MINUS, "-")
    if spec.startswith('"'):
        want = json.loads(spec)
        return (None if vals == [want] else f"{path.strip()} = {vals!r}, the page says {want!r}"), []
    if spec in ("true", "false", "null"):
        want = json.loads(spec)
        return (None if vals == [want] else f"{path.strip()} = {vals!r}, the page says {spec}"), []
    try:
        nums = [float(v) for v in vals]
    except (TypeError, ValueError):
        return f"{path.strip()} = {vals!r}: not numbers", []
    m = re.fullmatch(r"(<=?)\s*(\S+)", spec)
    if m:
        bound = float(m.group(2))
        ok = all((v < bound) if m.group(1) == "<" else (v <= bound) for v in nums)
        return (None if ok else f"{path.strip()} = {_fmt(nums)}, not all {m.group(1)} {m.group(2)}"), [m.group(2)]
    m = re.fullmatch(r"(\S+)\.\.(\S+)", spec)
    if m:
        ok = bool(nums) and at_digits(min(nums), m.group(1)) and at_digits(max(nums), m.group(2))
        why = None if ok else (f"{path.strip()}: from {_fmt([min(nums)]) if nums else '-'} to "
                               f"{_fmt([max(nums)]) if nums else '-'}, the page says {m.group(1)}..{m.group(2)}")
        return why, [m.group(1), m.group(2)]
    words = _value_words(spec)
    if len(words) != len(nums):
        return f"{path.strip()} has {len(nums)} values ({_fmt(nums)}), the page gives {len(words)}", words
    bad = [f"{_fmt([v])} (page {w})" for v, w in zip(nums, words) if not at_digits(v, w)]
    return (f"{path.strip()} = {', '.join(bad)}" if bad else None), words


def _fmt(nums):
    return ", ".join(f"{v:.6g}" for v in nums)


def check_text(output: str, patterns: list[str]):
    """Patterns found in order (each on a later line): ``(None or what differs, [numbers compared])``."""
    lines = output.splitlines()
    at, quoted = 0, []
    for pat in patterns:
        p = pat.strip().replace(MINUS, "-")
        quoted += [m.group(0) for m in re.finditer(NUMBER, re.sub(BOUND, lambda b: " " + b.group(2) + " ", p))]
        closest = None
        for k in range(at, len(lines)):
            ok, why = line_matches(p, lines[k], search=True, bounds=True)
            if ok:
                at = k + 1
                break
            if why and closest is None:
                closest = f"{lines[k].strip()!r}: {why}"
        else:
            why = f"not found after output line {at}: {p!r}" + (f"\n      closest: {closest}" if closest else "")
            return why, quoted
    return None, quoted


def quoted_in_region(numbers, region: str):
    """The numbers a check compares that the section's text does not show (by value: ``0.000`` is shown by ``0``)."""
    values = {float(t) for t in re.findall(NUMBER, region.replace(MINUS, "-"))}
    return [n for n in numbers if float(n.replace(MINUS, "-")) not in values]


def judge(item: Item, cmd: Command, result) -> str | None:
    """What is wrong with one command's result against the page, or None."""
    rc, out, err = result
    head = f"{item.where}: $ {cmd.text}\n    "
    if rc != cmd.exit_status:
        return head + f"exit status {rc}, expected {cmd.exit_status}\n    stderr: {err.strip()[-600:]}"
    if item.kind == "block":
        if cmd.expected is None:
            return None
        why = match_output(cmd.expected, out)
        return head + why if why else None
    data = _json_of(out)
    problems, quoted = [], []
    if data is not None:
        for ln in item.expectations:
            why, nums = check_json(data, ln)
            quoted += nums
            if why:
                problems.append(why)
    else:
        why, quoted = check_text(out, item.expectations)
        if why:
            problems.append(why)
    missing = quoted_in_region(quoted, item.region)
    if missing:
        problems.append(f"compares {', '.join(missing)}, which the section's text does not show")
    if not item.expectations:
        problems.append("the check compares nothing")
    return head + "\n    ".join(problems) if problems else None


# ----------------------------------------------------------------------------------------------- running
def scratch(directory: Path, files=None) -> Path:
    """A directory holding a copy of the repository's ``examples/`` and ``benchmarks/`` (and the page's ``file``
    blocks)."""
    directory.mkdir(parents=True, exist_ok=True)
    for name in COPIED:
        if not (directory / name).exists():
            shutil.copytree(ROOT / name, directory / name, ignore=shutil.ignore_patterns("__pycache__"))
    for name, text in (files or {}).items():
        (directory / name).write_text(text, encoding="utf-8")
    return directory


def environment() -> dict:
    """``zerocal`` and ``python`` of this interpreter first on the PATH; the tests' settings (no compiler, Agg), and
    80 columns (argparse wraps ``--help`` to ``COLUMNS``, which a terminal or a CI system may set).  Bytecode is
    written as a user's commands write it: the first command compiles a module, the later ones read it (each of
    some 150 commands compiling the package again would double the checker's CPU time)."""
    bindir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""), MPLBACKEND="Agg",
               ZEROCAL_COMPILE=os.environ.get("ZEROCAL_COMPILE", "never"), COLUMNS="80")
    env.pop("PYTHONPATH", None)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def run_commands(commands: list[str], cwd: Path, timeout: float = 1800):
    """Run commands in order in one bash (variables and ``cd`` carry over): ``[(status, stdout, stderr)]``."""
    log = cwd / ".docs-check"
    log.mkdir(exist_ok=True)
    script = ["set +e"]
    for k, text in enumerate(commands):
        script += ["{", text, f"}} >{log}/{k}.out 2>{log}/{k}.err </dev/null", f"echo $? >{log}/{k}.rc",
                   f"times >{log}/{k}.times"]
    proc = subprocess.run(["bash", "-c", "\n".join(script)], cwd=cwd, env=environment(), capture_output=True,
                          text=True, timeout=timeout)
    results = []
    for k in range(len(commands)):
        rc = log / f"{k}.rc"
        if not rc.exists():
            results.append((-1, "", f"not run (bash: {proc.stderr.strip()[-300:]})"))
            continue
        results.append((int(rc.read_text()), (log / f"{k}.out").read_text(errors="replace"),
                        (log / f"{k}.err").read_text(errors="replace")))
    return results


def cpu_seconds(directory: Path) -> list[float]:
    """CPU seconds (user + system, the commands' processes) of each command run in ``directory``, in order."""
    log, total, out = directory / ".docs-check", 0.0, []
    for k in range(len(list(log.glob("*.times")))):
        lines = (log / f"{k}.times").read_text().split("\n")
        now = sum(float(m) * 60 + float(s) for m, s in re.findall(r"(\d+)m([\d.]+)s", lines[1]))
        out.append(now - total)
        total = now
    return out


def command_key(text: str) -> str:
    """A command without its trailing ``# comment`` (outside quotes): two spellings of one run."""
    m = re.search(r"\s+#\s.*$", text)
    if m and text[:m.start()].count("'") % 2 == 0 and text[:m.start()].count('"') % 2 == 0:
        return text[:m.start()].strip()
    return text.strip()


def fast_commands(page: Page, shared=frozenset()):
    """``(todo, slots)``: the commands of the page's fast items in the order they run, and per item command
    ``(item, command, index into todo)``.  A check whose command ran before on the page takes that run; one whose
    command (``command_key``) is in ``shared`` takes the session's run of it (index ``None``)."""
    todo, slots = [], []
    seen = {}
    for it in page.items:
        if it.slow:
            continue
        for c in it.commands:
            key = command_key(c.text)
            if it.kind == "check" and key in seen:
                slots.append((it, c, seen[key]))
                continue
            if it.kind == "check" and key in shared:
                slots.append((it, c, None))
                continue
            seen.setdefault(key, len(todo))
            slots.append((it, c, len(todo)))
            todo.append(c.text)
    return todo, slots


def session_commands(pages) -> frozenset:
    """The commands (``command_key``) run once per session in a fresh directory, whose run a fast check of the same
    command takes: those more than one page shows (in a block or a check), and those of slow checks and of slow
    ``bash`` blocks' lines (``SharedCache.command`` runs them)."""
    where, slow = {}, set()
    for page in pages:
        for it in page.items:
            for c in it.commands:
                where.setdefault(command_key(c.text), set()).add(page.path)
            if it.slow and _one_run_per_command(it):
                slow |= {command_key(c.text) for c in it.commands}
    return frozenset(k for k, v in where.items() if len(v) > 1) | frozenset(slow)


def _one_run_per_command(item: Item) -> bool:
    """A slow item whose commands each run on their own (a check, one command, or a block that compares no
    output), not a slow console block of several commands run in order."""
    return len(item.commands) == 1 or (item.kind == "block" and all(c.expected is None for c in item.commands))


def run_page(page: Page, directory: Path, shared=frozenset(), shared_run=None):
    """The page's fast items in order in one directory: ``[problem]`` (empty when the page is right).

    ``shared_run(text)``: the session's ``(status, stdout, stderr)`` of a command in ``shared`` (a check's command
    that another page shows too, or a slow item: run once, in a fresh directory, for every page)."""
    scratch(directory, page.files)
    todo, slots = fast_commands(page, shared if shared_run else frozenset())
    results = run_commands(todo, directory) if todo else []
    return [p for p in (judge(it, c, results[k] if k is not None else shared_run(c.text)) for it, c, k in slots)
            if p]


class SharedCache:
    """Runs once per test session, also across pytest-xdist workers: a page's fast items, a slow item.

    Each run has a directory under ``root`` and a result file beside it; a lock file serialises the workers, so a
    second asker waits for the first run and reads its result (and may look at the files it wrote).
    """

    def __init__(self, root: Path, pages=None):
        self.root = root
        root.mkdir(parents=True, exist_ok=True)
        #: the commands run once per session in a fresh directory (a fast check of one takes that run)
        self.shared = session_commands([parse_page(p) for p in PAGES] if pages is None else pages)

    def _once(self, key: str, run):
        path, lock = self.root / f"{key}.json", self.root / f"{key}.lock"
        with open(lock, "w") as fh:
            try:
                import fcntl

                fcntl.flock(fh, fcntl.LOCK_EX)
            except ImportError:  # no file locks here: at worst two workers run the same thing
                pass
            if not path.exists():
                path.write_text(json.dumps(run(self.root / key)))
            return json.loads(path.read_text())

    def results(self, item: Item, files):
        """A slow item's ``[(status, stdout, stderr)]``, its commands run in a fresh directory; the lines of a
        slow bash block each in one of their own (they must not depend on each other), so that a check of one
        of them, on any page, takes its run."""
        if _one_run_per_command(item):
            return [self.command(c.text, files) for c in item.commands]
        key = "item-" + hashlib.sha256(json.dumps([c.text for c in item.commands]).encode()).hexdigest()[:16]
        return self._once(key, lambda d: run_commands([c.text for c in item.commands], scratch(d, files)))

    def command(self, text: str, files=None):
        """One command's ``(status, stdout, stderr)``, run in a fresh directory (once per session)."""
        key = "cmd-" + hashlib.sha256(command_key(text).encode()).hexdigest()[:16]
        return self._once(key, lambda d: run_commands([text], scratch(d, files))[0])

    def slow_results(self, page: Page, k: int):
        """The results of the page's slow item ``k``: a slow check's command, and each line of a slow bash block,
        run once per session for every page and check that names it."""
        item = page.items[k]
        if item.kind == "check":
            return [self.command(item.commands[0].text, page.files)]
        return self.results(item, page.files)

    def page(self, page: Page):
        """``(directory, problems)`` of the page's fast items, run in order in ``directory``."""
        key = "page-" + re.sub(r"\W", "_", _rel(page.path))
        problems = self._once(key, lambda d: run_page(page, d, self.shared,
                                                      lambda text: self.command(text, page.files)))
        return self.root / key, problems


def judge_item(item: Item, results):
    return [p for p in (judge(item, c, r) for c, r in zip(item.commands, results)) if p]
