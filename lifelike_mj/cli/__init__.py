"""The ``lifelike-mj`` command: one module per creature, and a registry for the shared verbs.

``lifelike-mj CREATURE ...`` runs a creature's own commands (:mod:`lifelike_mj.cli.butterfly`,
:mod:`~lifelike_mj.cli.fish`, :mod:`~lifelike_mj.cli.boids`); the shared verbs ``view``,
``render``, ``reproduce`` and ``bench`` take the creature as their first word and then only that
creature's options. Each creature module provides ``add_commands``, ``add_view_args``/``view``,
``add_render_args``/``render``, ``add_reproduce_args``/``reproduce``, ``add_bench_args``/``bench`` and
``add_export_args``/``export_window`` (:mod:`lifelike_mj.cli.export`; the 3D butterfly exports as ``butterfly3d``);
the commands call the creatures' library functions, so the command line and Python do the same thing.

Every error a user can cause ends in one sentence on stderr and exit status 2; imports are lazy so
that ``--help`` is instant and the GL backend can be chosen before MuJoCo is imported.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from lifelike_mj.cli.common import (
    CREATURES,
    SIMULATED,
    Parser,
    add_json,
    add_overwrite,
    check_outputs,
    count,
    creature,
    emit,
    join_negative_values,
    take_notes,
)
from lifelike_mj.errors import UserError


def _verb(sub, name: str, helptext: str, add: str, extra=None, creatures=CREATURES) -> None:
    p = sub.add_parser(name, help=helptext)
    per = p.add_subparsers(dest="what", required=True, parser_class=Parser, metavar="CREATURE")
    for c in creatures:
        mod = creature(c)
        if name == "view":  # what the live scene is, and its keys, listed by view CREATURE --help
            text = getattr(mod, "VIEW_HELP", mod.HELP)
            q = per.add_parser(c, help=text, description=text, epilog=getattr(mod, "view_keys", None))
        else:
            q = per.add_parser(c, help=mod.HELP)
        getattr(mod, add)(q)
        if extra is not None:
            extra(q)
        q.set_defaults(func=globals()[f"cmd_{name}"])


def _view_options(p) -> None:
    p.add_argument("--web", action="store_true",
                   help="serve MuJoCo's web viewer instead of opening a window (no display needed); open the "
                        "printed address in a browser")
    p.add_argument("--port", type=count(0, 65535), default=0, help="the web viewer's port (0: the first free from 8080)")
    p.add_argument("--host", default="localhost",
                   help="the web viewer's address to listen on; 0.0.0.0 or :: opens it to every network the machine is "
                        "on, with no password (a warning is printed)")


def web_options(args):
    """The web viewer's options of ``view --web``, checked, or None without ``--web``."""
    if not getattr(args, "web", False):
        if getattr(args, "host", "localhost") != "localhost" or getattr(args, "port", 0):
            raise UserError("--host and --port are for the web viewer: add --web.")
        return None
    from lifelike_mj.render.web import WebOptions

    return WebOptions(args.host, args.port).check()


def _render_options(p) -> None:
    p.add_argument("--out", required=True, help="FILE.mp4 or FILE.gif")
    p.add_argument("--fps", type=count(1, 240), default=30, help="frames per second of video, 1 to 240")
    p.add_argument("--width", type=count(16, 4096), default=640, help="frame width, pixels, 16 to 4096")
    p.add_argument("--height", type=count(16, 4096), default=480, help="frame height, pixels, 16 to 4096")
    add_overwrite(p)
    add_json(p)


def _reproduce_options(p) -> None:
    p.add_argument("--out", default=None, help="output folder (default reports/CREATURE; with all: OUT/CREATURE)")
    add_overwrite(p)


def _bench_options(p) -> None:
    p.add_argument("--out", help="also write the JSON here (.json)")
    add_overwrite(p)
    add_json(p)


def _command_words(args) -> list[str]:
    """The sub-command's words (``export fish``, ``butterfly evolve3d``) of parsed ``args``."""
    return [w for w in (getattr(args, "command", None), getattr(args, "what", None) or getattr(args, "sub", None))
            if isinstance(w, str)]


def _add_quiet(parser: Parser) -> None:
    """``--quiet`` on every command that runs (each leaf of the parser tree) that lacks one."""
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        if "--quiet" not in parser._option_string_actions:
            parser.add_argument("--quiet", action="store_true",
                                help="no progress bars and no closing 'done in' line on stderr")
        return
    for a in subs:
        for child in set(a.choices.values()):
            _add_quiet(child)


def build_parser() -> Parser:
    from lifelike_mj import __version__

    top = Parser(prog="lifelike-mj", description="Creatures that move like living things, by physics on MuJoCo.")
    top.add_argument("--version", action="version", version=f"lifelike-mj {__version__}")
    sub = top.add_subparsers(dest="command", required=True, parser_class=Parser)
    for c in CREATURES:
        creature(c).add_commands(sub)
    _verb(sub, "view", "open the MuJoCo viewer on a live simulation (--web: in a browser)", "add_view_args",
          _view_options, creatures=SIMULATED)
    _verb(sub, "render", "render a video offscreen", "add_render_args", _render_options)
    _verb(sub, "bench", "speed benchmark", "add_bench_args", _bench_options)
    from lifelike_mj.cli.export import add_export_verb

    add_export_verb(sub)
    p = sub.add_parser("reproduce", help="run a paper's experiments and write a report")
    per = p.add_subparsers(dest="what", required=True, parser_class=Parser, metavar="CREATURE")
    for c in (*CREATURES, "all"):
        q = per.add_parser(c, help=creature(c).HELP if c != "all" else "all three, one after another")
        if c == "all":
            creature("butterfly").add_reproduce_args(q)
        else:
            creature(c).add_reproduce_args(q)
        _reproduce_options(q)
        q.set_defaults(func=cmd_reproduce)
    _add_quiet(top)
    return top


def cmd_view(args) -> None:
    creature(args.what).view(args)


def cmd_render(args) -> None:
    check_outputs(args, files={"--out": (".mp4", ".gif")})
    info = creature(args.what).render(args)
    emit(args, info, f"wrote {info['frames']} frames to {args.out}")


def cmd_bench(args) -> None:
    check_outputs(args, files={"--out": (".json",)})
    r, human = creature(args.what).bench(args)
    if args.out:
        from lifelike_mj.io import write_json
        from lifelike_mj.provenance import provenance

        write_json(args.out, {**r, "provenance": provenance(**{k: v for k, v in vars(args).items() if k != "func"})})
    emit(args, r, human)


def cmd_reproduce(args) -> None:
    whats = CREATURES if args.what == "all" else (args.what,)
    from lifelike_mj.paths import check_output_dir

    for claim in (False, True):  # every folder checked before the first stage starts, then claimed
        for what in whats:
            out = Path(args.out or "reports") / what if (args.what == "all" or not args.out) else Path(args.out)
            make = 2 if (args.what == "all" or not args.out) else 1  # OUT (or reports) and its creature's folder
            check_output_dir(out, "--out", ("report.md", "results.json"), overwrite=args.overwrite, claim=claim,
                             make=make)
    import time

    from lifelike_mj.progress import duration_text

    t0 = time.perf_counter()
    for what in whats:
        out = Path(args.out or "reports") / what if (args.what == "all" or not args.out) else Path(args.out)
        creature(what).reproduce(out, args)
        print(f"report written to {out / 'report.md'}")
    if len(whats) > 1:
        print(f"all reports written in {duration_text(time.perf_counter() - t0)}")


def _leaf(parser: argparse.ArgumentParser, args: argparse.Namespace) -> argparse.ArgumentParser:
    """The parser of the command ``args`` ran (``lifelike-mj fish swim``'s, not the top one)."""
    while True:
        sub = next((a for a in parser._actions if isinstance(a, argparse._SubParsersAction)), None)
        name = getattr(args, sub.dest, None) if sub is not None else None
        if sub is None or name not in sub.choices:
            return parser
        parser = sub.choices[name]


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] in (["render"], ["reproduce"]) or (argv[:1] == ["fish"] and any(a.startswith("--video") for a in argv)):
        from lifelike_mj.render.gl import ensure_gl_backend

        ensure_gl_backend()  # before anything imports mujoco
    from lifelike_mj.provenance import set_command

    set_command(argv)
    from lifelike_mj.io import held_claims, release_claims

    before = held_claims()
    import time

    from lifelike_mj import progress

    try:
        parser = build_parser()
        args, extra = parser.parse_known_args(join_negative_values(argv))
        if extra:  # said by the command's own parser, which knows its options' names
            _leaf(parser, args).error(f"unrecognized arguments: {' '.join(extra)}")
        progress.set_enabled(not getattr(args, "quiet", False))
        t0 = time.perf_counter()
        args.func(args)
        for text in take_notes():
            print(f"note: {text}", file=sys.stderr)
        progress.done_line(" ".join(["lifelike-mj", *_command_words(args)]), time.perf_counter() - t0)
    except UserError as exc:
        take_notes()  # an error is one sentence
        print(f"lifelike-mj: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        why = f": {exc.args[0]}" if exc.args and isinstance(exc.args[0], str) and " " in exc.args[0] else ""
        print(f"lifelike-mj: interrupted{why}.", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader went away (`lifelike-mj ... | head`): stop quietly
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # the file system refused (no space, read-only, name too long ...): one sentence
        print(f"lifelike-mj: error: {file_system_error(exc)}", file=sys.stderr)
        return 2
    finally:
        release_claims(keep=before)
    return 0


def file_system_error(exc: OSError) -> str:
    """One sentence for an ``OSError`` raised while reading or writing a file (what, which file, why)."""
    import errno

    why = {errno.ENOSPC: "there is no space left on the device", errno.EDQUOT: "the disk quota is exhausted",
           errno.EROFS: "the file system is read-only", errno.EACCES: "permission is denied",
           errno.EPERM: "the operation is not permitted", errno.ENAMETOOLONG: "the name is too long for the file system",
           errno.EISDIR: "it is a folder", errno.ENOTDIR: "a part of its path is not a folder",
           errno.ENOENT: "it does not exist", errno.EMFILE: "too many files are open"}.get(exc.errno or -1,
                                                                                            exc.strerror or str(exc))
    name = exc.filename if exc.filename is not None else ""
    name = str(name)
    if len(name) > 100:
        name = name[:60] + "..." + name[-30:]
    return f"the file system refused {name or 'a file'}: {why}."
