"""What every creature's command line shares: the parser that turns usage errors into one sentence,
output as text or ``--json``, and checks of numbers given on the command line."""

from __future__ import annotations

import argparse

from lifelike_mj.errors import UserError


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Help that shows every option's default once, readably (:func:`show_default`), except empty ones and where
    the help already says it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        empty = action.default is None or action.default is False or action.default == argparse.SUPPRESS
        if "%(default)" in text or "default" in text.lower() or empty or not action.option_strings:
            return text
        return f"{text} (default: {show_default(action.default).replace('%', '%%')})"


def show_default(value) -> str:
    """A default as a reader wants it: ``1/1200`` for a small float that is one over a whole number, else at
    most 6 significant digits; a list comma-joined (``none`` when empty)."""
    if isinstance(value, float):
        if 0.0 < abs(value) < 0.01 and abs(1.0 / value - round(1.0 / value)) < 1e-6 * abs(1.0 / value):
            return f"1/{round(1.0 / value)}"
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(show_default(v) for v in value) if value else "none"
    return str(value)


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one sentence (exit status 2, no usage block) and whose help
    shows the defaults."""

    def __init__(self, *args, **kwargs) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)

    def format_help(self) -> str:
        if callable(self.epilog):  # made when asked for (it may import the creature), not when the parser is built
            self.epilog = self.epilog()
        return super().format_help()

    def error(self, message: str):  # one sentence, exit 2 (argparse prints usage otherwise)
        raise UserError(f"{self._plain(message)} (see '{self.prog} --help').")

    def _plain(self, message: str) -> str:
        """argparse's message in the user's words: a misspelt command or choice, or an unknown option, named with
        the nearest known one."""
        import difflib
        import re

        def near(word: str, known) -> str:
            close = difflib.get_close_matches(word, list(known), n=1, cutoff=0.6)
            return f" (did you mean {close[0]!r}?)" if close else ""

        m = re.match(r"argument (\S+): invalid choice: '?(.*?)'? \(choose from (.*)\)$", message)
        if m:
            dest, word = m.group(1), m.group(2)
            action = next((a for a in self._actions if dest in (a.dest, a.metavar, *a.option_strings)), None)
            known = [str(c) for c in (action.choices or ())] if action is not None else []
            if isinstance(action, argparse._SubParsersAction):
                return (f"{self.prog} has no command {word!r}{near(word, known)}; its commands are "
                        f"{', '.join(known)}")
            return f"{dest} {word!r} is not one of {', '.join(known)}{near(word, known)}"
        m = re.match(r"unrecognized arguments: (.*)$", message)
        if m:
            word = m.group(1).split()[0].split("=")[0]
            if word.startswith("-"):
                known = {o[2:]: o for o in self._option_string_actions if o.startswith("--")}
                close = difflib.get_close_matches(word.lstrip("-"), list(known), n=1, cutoff=0.75)
                hint = f" (did you mean {known[close[0]]!r}?)" if close else ""
                return f"{self.prog} has no option {word!r}{hint}"
            return f"{self.prog} takes no argument {word!r} here"
        return message


def num(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False, unit: str = ""):
    """An argparse ``type``: a finite number in ``[lo, hi]`` (``(lo, hi]`` with ``lo_open``); the range
    is in the error sentence. Numbers like ``1e3``, negative values (``-2``) and fractions (``1/1200``, as
    ``1.0 / 1200``) are accepted."""
    from lifelike_mj import checks

    def parse(text: str) -> float:
        try:
            if "/" in text:
                a, b = text.split("/")
                v = float(a) / float(b)
            else:
                v = float(text)
        except (ValueError, ZeroDivisionError):
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        try:
            return checks.number("the value", v, lo, hi, lo_open=lo_open, unit=unit)
        except UserError as exc:
            raise argparse.ArgumentTypeError(str(exc).removeprefix("the value ").rstrip(".")) from None

    parse.__name__ = "number"
    return parse


def count(lo: int = 0, hi: int | None = None):
    """An argparse ``type``: a whole number in ``[lo, hi]`` (``1e6`` is accepted when it is whole)."""
    rng = f"from {lo:,} to {hi:,}" if hi is not None else f"of at least {lo:,}"

    def parse(text: str) -> int:
        try:
            v = float(text) if any(c in text for c in ".eE") else int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a whole number {rng}, got {text!r}") from None
        if v != v or v in (float("inf"), float("-inf")) or int(v) != v or v < lo or (hi is not None and v > hi):
            raise argparse.ArgumentTypeError(f"must be a whole number {rng}, got {text!r}")
        return int(v)

    parse.__name__ = "whole number"
    return parse


def join_negative_values(argv: list[str]) -> list[str]:
    """``--wind -2,0`` as ``--wind=-2,0``: argparse would read a value that starts with ``-`` as an
    option unless it is a plain negative number."""
    import re

    out: list[str] = []
    for tok in argv:
        if out and re.match(r"^-[0-9.]", tok) and out[-1].startswith("--") and "=" not in out[-1]:
            out[-1] = f"{out[-1]}={tok}"
        else:
            out.append(tok)
    return out


def emit(args: argparse.Namespace, data: dict, human: str) -> None:
    """Print ``data`` as strict indented JSON with ``--json`` (NaN as ``null``, named under ``"undefined"``),
    else the sentence ``human``."""
    from lifelike_mj.io import dumps

    print(dumps(data) if getattr(args, "json", False) else human)


def add_json(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true",
                   help="print the results as JSON on stdout (progress bars stay on stderr)")


def add_overwrite(p: argparse.ArgumentParser) -> None:
    p.add_argument("--overwrite", action="store_true", help="replace output files that already exist")


def add_seed(p: argparse.ArgumentParser, default: int = 0) -> None:
    p.add_argument("--seed", type=count(0, 2**32 - 1), default=default,
                   help="random seed, 0 to 2^32-1: the same seed gives the same result")


def add_run_files(p: argparse.ArgumentParser, out_help: str) -> None:
    """``--checkpoint``, ``--resume``, ``--overwrite``, ``--out`` and ``--quiet`` of an evolution."""
    p.add_argument("--checkpoint", default=None, help="checkpoint file (default: OUT.ckpt), written every generation")
    p.add_argument("--resume", action="store_true", help="continue from the checkpoint")
    p.add_argument("--overwrite", action="store_true", help="replace an existing --out and checkpoint (a new run)")
    p.add_argument("--out", default=None, help=out_help)
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def seeds(text: str, what: str = "--seeds", limit: int | None = None) -> list[int]:
    """``0-4`` or ``0,3,7`` as a list of seeds (at most ``limit``, :data:`~lifelike_mj.checks.MAX_SEEDS` by default,
    refused before the list is built)."""
    from lifelike_mj import checks

    limit = checks.MAX_SEEDS if limit is None else limit
    bad = UserError(f"{what} must look like 0-4 or 0,1,2 (seeds from 0 to 2^32-1, a range low to high), got {text!r}.")
    try:
        if "-" in text.lstrip("-"):
            a, b = (int(x) for x in text.split("-"))
            ends = [a, b]
        else:
            ends = [int(x) for x in text.split(",")]
    except ValueError:
        raise bad from None
    if not ends or min(ends) < 0 or max(ends) > 2**32 - 1 or ("-" in text and ends[1] < ends[0]):
        raise bad
    n = ends[1] - ends[0] + 1 if "-" in text else len(ends)
    checks.work(f"{what} {text}", n, limit, "seeds", "a shorter range" if "-" in text else "")
    return list(range(ends[0], ends[1] + 1)) if "-" in text else ends


def add_executor(p: argparse.ArgumentParser, default: str = "process", serial: str = "this process") -> None:
    """``--executor``, ``--workers``, ``--ray-address`` (checked together by :func:`check_executor`); ``serial``: what
    the serial executor is, in the help."""
    p.add_argument("--executor", default=default, choices=("serial", "process", "ray"),
                   help=f"where candidates are evaluated: serial ({serial}), process (a pool on this machine) or ray")
    p.add_argument("--workers", type=count(1, 1024), default=None,
                   help="worker processes (process) or chunks per batch (ray), 1 to 1024 (default: all cores)")
    p.add_argument("--ray-address", default=None,
                   help="Ray cluster to join, HOST:PORT or ray://HOST:PORT (default: start a local one); only with "
                        "--executor ray")


def check_executor(args: argparse.Namespace) -> None:
    """Refuse executor options that would be ignored; check a Ray address before any work."""
    if args.executor == "serial" and args.workers is not None:
        raise UserError("--workers does not apply to --executor serial.")
    if args.ray_address is not None:
        if args.executor != "ray":
            raise UserError("--ray-address only applies to --executor ray.")
        from lifelike_mj.evolve.evaluators import check_ray_address

        check_ray_address(args.ray_address)


def check_outputs(args: argparse.Namespace, files: dict[str, tuple[str, ...]] | None = None,
                  folders: dict[str, tuple[str, ...]] | None = None) -> None:
    """Before any work: each option in ``files`` (name -> allowed suffixes) names a file that can be written
    and does not exist unless ``--overwrite``; each option in ``folders`` (name -> the files it will hold)
    names a folder whose files do not exist yet unless ``--overwrite``; then each is claimed for this run
    (:func:`lifelike_mj.io.claim`: a second run on the same output stops at once, naming this one)."""
    from lifelike_mj.paths import check_output_dir, check_output_file

    overwrite = bool(getattr(args, "overwrite", False))
    for claim in (False, True):  # every output checked before the first is claimed (a refusal leaves no trace)
        for opt, suffixes in (files or {}).items():
            value = getattr(args, opt.lstrip("-").replace("-", "_"), None)
            if value:
                check_output_file(value, opt, suffixes=suffixes, overwrite=overwrite, claim=claim)
        for opt, names in (folders or {}).items():
            value = getattr(args, opt.lstrip("-").replace("-", "_"), None)
            if value:
                check_output_dir(value, opt, names, overwrite=overwrite, claim=claim)


_NOTES: list[str] = []


def note(text: str) -> None:
    """A one-line note for the user (an old spelling still taken), printed on stderr once the command has run
    (:func:`take_notes`), so that an error stays one sentence."""
    if text not in _NOTES:
        _NOTES.append(text)


def take_notes() -> list[str]:
    """The notes gathered so far, emptied."""
    out = list(_NOTES)
    _NOTES.clear()
    return out


class _WindAction(argparse.Action):
    """Stores a wind given as where it comes from (``from``) or where it blows to (``to``) in the command's own
    meaning (``native``); the old spelling ``--wind`` (``old``) stores it as given, with a one-line note."""

    def __init__(self, *args, sense: str = "", native: str = "", **kwargs) -> None:
        self.sense, self.native = sense, native
        super().__init__(*args, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        if self.sense == "old":
            meaning = "where it comes from" if self.native == "from" else "where it blows to"
            note(f"--wind is now --wind-{self.native} ({meaning}); --wind goes in the next release.")
            v = tuple(values)
        else:
            v = tuple(values) if self.sense == self.native else tuple(-x for x in values)
        setattr(namespace, self.dest, tuple(x + 0.0 for x in v))  # + 0.0: no -0.0 from a negated 0


def wind_vector(dims: int, names: str, bound: float | None = None):
    """An argparse ``type``: ``dims`` finite numbers (m/s), comma-separated, named ``names`` in the message; each
    within +-``bound`` where one is given."""
    import math

    word = {2: "two", 3: "three"}[dims]

    def parse(text: str) -> tuple[float, ...]:
        try:
            v = tuple(float(x) for x in text.split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(f"needs {word} numbers {names} in m/s, got {text!r}") from None
        if len(v) != dims:
            raise argparse.ArgumentTypeError(f"needs {word} numbers {names} in m/s, got {text!r}")
        if not all(math.isfinite(x) for x in v):
            raise argparse.ArgumentTypeError(f"needs {word} numbers {names} in m/s, all finite, got {text!r}")
        if bound is not None and not all(abs(x) <= bound for x in v):
            raise argparse.ArgumentTypeError(f"needs {word} numbers {names} in m/s, each within +-{bound:g}, "
                                             f"got {text!r}")
        return v

    return parse


def add_wind(p: argparse.ArgumentParser, dims: int, native: str, axes: str, what: str = "",
             bound: float | None = None) -> None:
    """``--wind-from`` and ``--wind-to`` (one or the other: the same wind, negated), stored in ``args.wind`` in the
    command's own convention ``native`` (``"from"``: the planar flight's, where the paper's wind map says the wind
    comes from; ``"to"``: the 3D flight's, the air's velocity); ``--wind``, the spelling of before 0.3, keeps the
    command's own meaning for one more release, with a one-line note. ``axes``: the components' names;
    ``bound``: the largest component (m/s), or None where the model checks it."""
    names = ",".join(axes.split(", ")).upper()
    kind = wind_vector(dims, names, bound)
    g = p.add_mutually_exclusive_group()
    zero = tuple(0.0 for _ in range(dims))
    first = axes.split(", ")[0]
    example = "2,0" + ",0" * (dims - 2)
    ahead = "ahead: a head wind" if first == "forward" else f"+{first}"
    behind = "forward: a tail wind" if first == "forward" else f"toward +{first}"
    g.add_argument("--wind-from", dest="wind", type=kind, default=zero, action=_WindAction, sense="from",
                   native=native, metavar=names,
                   help=f"{what}wind ({axes}) in m/s, given as where it comes from ({example} comes from {ahead})")
    g.add_argument("--wind-to", dest="wind", type=kind, default=zero, action=_WindAction, sense="to", native=native,
                   metavar=names, help=f"{what}wind ({axes}) in m/s, given as where it blows to, the air's velocity "
                                       f"({example} blows {behind})")
    g.add_argument("--wind", dest="wind", type=kind, default=zero, action=_WindAction, sense="old", native=native,
                   metavar=names, help=f"the older spelling of --wind-{native}")


#: The creatures, in the order of ``reproduce all``: each a module ``lifelike_mj.cli.NAME``.
CREATURES = ("butterfly", "fish", "boids")
#: Every simulated creature that ``view``, ``export`` and scenes take, in the order of the help: the creatures,
#: with the 3D butterfly (``butterfly3d``, a part of ``lifelike-mj butterfly``) after the planar one.
SIMULATED = ("butterfly", "butterfly3d", "fish", "boids")


def creature(name: str):
    """The command-line module of creature ``name`` (one of :data:`SIMULATED`)."""
    import importlib

    return importlib.import_module(f"lifelike_mj.cli.{name}")
