"""Every command the README and docs/ show runs as written.

The commands are read from the files: every line of a ```bash block and every inline `lifelike-mj ...`,
`python examples/...`, `python benchmarks/...` and `python docs/...` span (a span may wrap lines). Each is then
checked by the first rule of :func:`rule` that fits it, and no command is left without one:

* setup lines (``python3 -m venv``, ``. .venv/bin/activate``, ``pip install``) and the test command are skipped,
  each by its own rule, as is the API reference's command, which ``tests/test_api_docs.py`` runs as written;
* every ``lifelike-mj ...`` command parses with the real parser after the same preprocessing ``main`` does; a
  pattern (``--controller FILE``, ``CREATURE``, ``paper|rich``) has each alternative spelled out, or, where a word
  stands for something, its command words parse with ``--help`` and every option it shows is one of that
  command's; the commands in :data:`RUN` and :data:`RUN_SLOW` (measured to take under about 10 s and under about
  2 min) really run, as a user's shell runs them, from a fresh folder (``tmp_path``, where the repository's
  ``examples`` and ``benchmarks`` folders are linked so that the paths shown resolve, and outputs land);
* ``python examples/X.py ...`` and ``python benchmarks/X.py ...`` answer ``--help`` from another folder, and show
  every option the docs give them; a ``python -c`` line runs; Blender's lines name a script that exists.
"""

from __future__ import annotations

import functools
import os
import py_compile
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: The files whose commands are checked.
DOC_FILES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
#: Words that stand for something the reader chooses.
PLACEHOLDERS = {"FILE", "NAME", "CREATURE", "COMMAND", "DIR", "PY", "S", "V", "SCENE.json", "...", "OUT", "PRESET"}
#: Files that a command shown elsewhere in the docs writes (a training run): a command that reads one is parsed.
TRAINED = {"my_net.json", "ppo.json", "ppo3d.json", "net.json", "ppo_pitch.json", "robust.json", "mine.json",
           "monarch.json", "net88.json", "flight.glb", "flight.blend", "tank.glb", "flock.glb", "garden.glb"}


@dataclass(frozen=True)
class Shown:
    """A command as the docs show it: where (``file:line``) and its words as written (comment and remark off)."""

    where: str
    text: str

    def __str__(self) -> str:
        return f"{self.where}: {self.text}"


def _without_comment(line: str) -> str:
    """A shell line without its ``# comment`` (a ``#`` outside quotes that starts a word)."""
    quote = ""
    for i, c in enumerate(line):
        if quote:
            quote = "" if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i].rstrip()
    return line.rstrip()


def _parts(text: str) -> list[str]:
    """A shell line's commands (``a && b``)."""
    return [p.strip() for p in text.split("&&") if p.strip()]


#: How an inline span that is a command starts.
_INLINE_STARTS = ("lifelike-mj", "python examples/", "python benchmarks/", "python docs/", "python -c ", "pip install ")


def shown_commands() -> list[Shown]:
    """Every command of :data:`DOC_FILES`, in order (a line's ``&&`` parts one by one)."""
    out: list[Shown] = []
    for path in DOC_FILES:
        name = path.relative_to(ROOT).as_posix()
        text = path.read_text(encoding="utf-8")
        fence = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", flags=re.S | re.M)
        for m in fence.finditer(text):
            if m.group(1) not in ("bash", "sh", "shell"):
                continue
            first = text[: m.start()].count("\n") + 2
            for i, line in enumerate(m.group(2).splitlines()):
                for part in _parts(_without_comment(line)):
                    out.append(Shown(f"{name}:{first + i}", part))
        outside = fence.sub(lambda m: "\n" * m.group(0).count("\n"), text)
        offset = 0
        for k, piece in enumerate(outside.split("`")):
            span = " ".join(piece.split())
            if k % 2 and span.startswith(_INLINE_STARTS) and " " in span:
                line = outside[:offset].count("\n") + 1
                out.extend(Shown(f"{name}:{line}", part) for part in _parts(span))
            offset += len(piece) + 1
    return out


# ---- what each command gets ----------------------------------------------------------------------------------------

#: ``lifelike-mj`` commands that really run in the quick tests (each measured at under about 5 s on 2 cores, warm numba
#: cache; a cold cache adds its compile once).
RUN = {
    "lifelike-mj butterfly speed-limit --body-area-cm2 1.53 --json",
    "lifelike-mj butterfly forces --json",
    "lifelike-mj butterfly trim --json",
    "lifelike-mj butterfly timestep --json",
    "lifelike-mj butterfly fly --controller simple_rule --phi-up-deg 14 --out fly14",
    "lifelike-mj butterfly fly --controller ann_paper --y0 10 --json",
    "lifelike-mj butterfly fly --controller simple_rule --json",
    "lifelike-mj butterfly compare --controller simple_rule --config paper --json",
    "lifelike-mj fish drag-check --json",
    "lifelike-mj fish swim --duration 1 --json",
    "lifelike-mj fish swim --preset school --tank 3,3,1",
    "lifelike-mj butterfly fly3d --task course --seed 100 --out flight3d",
    "lifelike-mj butterfly measure3d",
    "lifelike-mj export fish --n 10 --seed 1 --duration 20 --out tank.glb",
}
#: ``lifelike-mj`` commands that really run in the slow tests (measured at 5 s to 1 min each).
RUN_SLOW = {
    "lifelike-mj butterfly trim --backend mujoco --dt 0.000833333 --json",
    "lifelike-mj butterfly fly --controller simple_rule --backend mujoco --config rich --y0 5 --wind-from 2,0",
    "lifelike-mj butterfly compare --controller simple_rule --config rich --json",
    "lifelike-mj butterfly fly --controller ann_paper --wind-from -2,0 --inputs ground",
    "lifelike-mj butterfly fly --controller simple_rule --backend mujoco --duration 1 --json",
    "lifelike-mj butterfly windmap --controller ann_paper --inputs air --json --plot map.png",
    "lifelike-mj butterfly assess --controller ann_robust --json",
    "lifelike-mj render butterfly --out butterfly.mp4",
    "lifelike-mj fish swim --preset B-D --n 10 --duration 30 --json --out fish_bd",
    "lifelike-mj fish swim --preset NB-ND --seed 3 --video nbnd.mp4 --camera follow",
    "lifelike-mj render fish --preset B-D --camera side --duration 10 --out fish.mp4",
    "lifelike-mj fish swim",
    "lifelike-mj fish swim --preset pair --fish 2 --tank 1.12,1.12,0.3",
    "lifelike-mj fish swim --fish 10 --duration 120 --seed 11 --json",
    "lifelike-mj boids run --steps 10 --json",
    "lifelike-mj boids run --preset 4c --n 300 --seed 0 --json --plot 4c.png --out run_4c",
    'lifelike-mj boids run --wa "0.5,-0.15;-0.15,0.5" --wc "0.01,0.01;0.01,0.01" --dims 2',
    "lifelike-mj render boids --preset 5b --out boids.mp4",
    "lifelike-mj butterfly strobe3d --out beat.png",
    "lifelike-mj butterfly assess3d",
    "lifelike-mj butterfly assess3d --wind-to 1,0,0 --gusts 0.5 --vertical-gusts 0.25",
    "lifelike-mj butterfly assess3d --controller monarch --json",
    "lifelike-mj butterfly assess3d --controller benchmarks/results/withdrawn/steer.json --dt 1/1200",
    "lifelike-mj butterfly measure3d --controller benchmarks/results/withdrawn/steer.json",
    "lifelike-mj butterfly land3d --flowers 11 --picture land.png",
    "lifelike-mj butterfly land3d --flowers 4 --seed 360 --picture land.png",
    "lifelike-mj butterfly land3d",
    "lifelike-mj butterfly land3d --picture land.png",
    "lifelike-mj export butterfly3d --task course --seed 101 --duration 6 --out flight.glb",
    "lifelike-mj export butterfly3d --task level --start 5 --duration 2 --loop --out cycle.glb",
    "lifelike-mj export boids --preset 5b --n 300 --steps 1500 --out flock.glb",
    "lifelike-mj export scene examples/scenes/garden.json --out garden.glb",
}


def _words(text: str) -> list[str]:
    return shlex.split(text)


def _alternatives(text: str) -> list[str]:
    """``--config paper|rich`` as one command per alternative (a remark in brackets at the end left off)."""
    text = re.sub(r"\s*\([^()]*\)$", "", text)
    words = _words(text)
    for i, w in enumerate(words):
        if "|" in w and not w.startswith(("'", '"')) and "=" not in w:
            return [a for alt in w.split("|") for a in _alternatives(shlex.join([*words[:i], alt, *words[i + 1:]]))]
    return [text]


def rule(text: str) -> tuple[str, str]:
    """``(what is done, why)`` for a command as written; the first rule that fits."""
    words = _words(text)
    if words[:3] in (["python3", "-m", "venv"], ["python", "-m", "venv"]):
        return "skip", "setup: makes the virtual environment"
    if words[0] in (".", "source"):
        return "skip", "setup: activates the virtual environment"
    if words[:2] == ["pip", "install"]:
        return "skip", "setup: installs the package (the test's environment is installed already)"
    if words[:3] == ["python", "-m", "pytest"]:
        return "skip", "the test suite itself"
    if "pdoc" in words:
        return "skip", "the API reference: tests/test_api_docs.py runs it exactly as written"
    if words[0] == "blender":
        return "blender", "needs Blender (tests/export runs the script in it): the script exists and compiles"
    if words[0] == "python" and words[1] == "-c":
        return "python-c", "runs"
    if words[0] == "python" and words[1].startswith(("examples/", "benchmarks/")):
        return "help", "answers --help from another folder, listing every option shown"
    if words[0] == "python" and words[1].startswith("docs/"):
        return "compiles", "regenerates the shipped figures inside the repository (minutes): the script compiles"
    if words[0] == "lifelike-mj:" or ": done in" in text:
        return "skip", "a line the commands print, not a command"
    if words[0] != "lifelike-mj":
        return "unknown", "no rule fits: add one"
    if any(w in PLACEHOLDERS or w.endswith("...") for w in words):
        return "pattern", "a pattern: its command words parse with --help and every option shown is the command's"
    if _is_group(words[1:]):
        return "pattern", "names a group of commands: its --help answers"
    if _names_a_command_needing_options(words[1:]):
        return "pattern", "names a command in prose (it needs options to run): its --help answers"
    if text in RUN:
        return "run", "runs (measured under about 10 s)"
    if text in RUN_SLOW:
        return "run-slow", "runs (slow)"
    if len(words) > 1 and words[1] == "view":
        return "parse", "opens a window or a web server: parsed"
    if "--ray-address" in words:
        return "parse", "needs a Ray cluster: parsed"
    if "--mesa-python" in words:
        return "parse", "needs a Python with Mesa: parsed"
    if "--resume" in words:
        return "parse", "continues an earlier run's checkpoint: parsed"
    if any(w in TRAINED or w.rsplit("/", 1)[-1] in TRAINED for w in words if not w.startswith("-")) and "--out" not in words:
        return "parse", "reads a file that a training run shown before writes: parsed"
    return "parse", "takes longer than a test may (an evolution, a report, a benchmark, a long run): parsed"


@functools.cache
def _parser():
    from lifelike_mj.cli import build_parser

    return build_parser()


def _leaf(words: list[str]):
    """The parser of the command named by ``words`` (``["butterfly", "evolve3d"]``) and the words left."""
    import argparse

    p = _parser()
    rest = list(words)
    while rest:
        subs = [a for a in p._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs or rest[0] not in subs[0].choices:
            break
        p = subs[0].choices[rest.pop(0)]
    return p, rest


def _is_group(words: list[str]) -> bool:
    """Whether ``words`` name a group of commands (``export``), not one that runs."""
    import argparse

    parser, left = _leaf(words)
    return not left and any(isinstance(a, argparse._SubParsersAction) for a in parser._actions)


def _names_a_command_needing_options(words: list[str]) -> bool:
    """Whether ``words`` are a command's words alone (no option) and it cannot run without some
    (``lifelike-mj butterfly evolve`` named in a sentence)."""
    from lifelike_mj.errors import UserError

    parser, left = _leaf(words)
    if left:
        return False
    try:
        parser.parse_args([])
    except UserError as exc:
        return "required" in str(exc)
    return False


def _checks() -> list[tuple[Shown, str, str]]:
    out = []
    for s in shown_commands():
        for alt in _alternatives(s.text):
            what, why = rule(alt)
            out.append((Shown(s.where, alt), what, why))
    return out


CHECKS = _checks()


def _ids(items) -> list[str]:
    return [f"{s.where} {s.text[:70]}" for s, _, _ in items]


def _of(*kinds: str):
    return [c for c in CHECKS if c[1] in kinds]


def _once(*kinds: str):
    """:func:`_of`, a command shown in several places kept where it is first shown (it runs once: the same words run
    the same way)."""
    seen: set[str] = set()
    return [c for c in _of(*kinds) if not (c[0].text in seen or seen.add(c[0].text))]


def test_the_docs_show_commands_and_each_gets_a_rule():
    """The reading finds the commands (a floor, so that a broken reader fails) and every one has a rule."""
    assert len(CHECKS) >= 150, len(CHECKS)
    kinds = {what for _, what, _ in CHECKS}
    assert {"skip", "run", "parse", "help", "pattern"} <= kinds, kinds
    assert not _of("unknown"), [str(s) for s, _, _ in _of("unknown")]
    texts = {s.text for s, _, _ in CHECKS}
    assert RUN <= texts and RUN_SLOW <= texts, (RUN | RUN_SLOW) - texts  # the run lists name commands still shown
    for where in ("README.md", "docs/animators.md", "docs/results.md", "docs/performance.md"):
        assert any(s.where.startswith(where + ":") for s, _, _ in CHECKS), where


def test_the_setup_lines_are_skipped_by_name():
    skipped = {s.text: why for s, what, why in CHECKS if what == "skip"}
    assert skipped["pip install ."].startswith("setup:")
    assert skipped["python3 -m venv .venv"].startswith("setup:")
    assert skipped[". .venv/bin/activate"].startswith("setup:")
    assert skipped["python -m pytest -q"] == "the test suite itself"


# ---- parsing ---------------------------------------------------------------------------------------------------------


def _parse(text: str):
    from lifelike_mj.cli import build_parser
    from lifelike_mj.cli.common import join_negative_values

    return build_parser().parse_args(join_negative_values(_words(text)[1:]))


@pytest.mark.parametrize("shown, what, why", _of("run", "run-slow", "parse"), ids=_ids(_of("run", "run-slow", "parse")))
def test_each_lifelike_mj_command_parses(shown, what, why):
    args = _parse(shown.text)
    assert callable(args.func)


@pytest.mark.parametrize("shown, what, why", _of("pattern"), ids=_ids(_of("pattern")))
def test_each_pattern_names_a_command_and_its_options(shown, what, why, capsys):
    """``lifelike-mj export CREATURE ... --out FILE``: the words before the first placeholder name a command (its
    ``--help`` answers), and every option shown is one of that command's (for ``CREATURE``: of every creature's)."""
    from lifelike_mj.cli import main

    words = _words(shown.text)[1:]
    head = []
    for w in words:
        if w in PLACEHOLDERS or w.endswith("...") or w.startswith("-"):
            break
        head.append(w)
    with pytest.raises(SystemExit) as exc:
        main([*head, "--help"])
    assert exc.value.code == 0
    assert "usage:" in capsys.readouterr().out
    options = [w.split("=")[0] for w in words if w.startswith("--")]
    parser, left = _leaf(head)
    if "CREATURE" in words:
        import argparse

        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        leaves = list(subs[0].choices.values())
    else:
        assert not left, left
        leaves = [parser]
    for option in options:
        assert all(option in leaf._option_string_actions for leaf in leaves), (option, shown.text)


# ---- running -----------------------------------------------------------------------------------------------------


def _elsewhere(tmp_path: Path) -> dict[str, str]:
    """A fresh folder for a command (the repository's examples and benchmarks linked into it, so that the paths the
    docs show resolve), and the environment a user's shell gives it (the venv's scripts first on the PATH)."""
    for name in ("examples", "benchmarks"):
        (tmp_path / name).symlink_to(ROOT / name, target_is_directory=True)
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    return env


def _run(text: str, tmp_path: Path, timeout: float) -> subprocess.CompletedProcess:
    env = _elsewhere(tmp_path)
    return subprocess.run(["bash", "-c", text], capture_output=True, text=True, cwd=tmp_path, env=env, timeout=timeout)


@pytest.mark.parametrize("shown, what, why", _once("run"), ids=_ids(_once("run")))
def test_each_cheap_command_runs_as_written(shown, what, why, tmp_path):
    r = _run(shown.text, tmp_path, 300)
    assert r.returncode == 0, f"{shown}\n{r.stderr[-3000:]}"
    assert re.search(r"lifelike-mj .*: done in ", r.stderr), r.stderr[-500:]


@pytest.mark.slow
@pytest.mark.parametrize("shown, what, why", _once("run-slow"), ids=_ids(_once("run-slow")))
def test_each_slower_command_runs_as_written(shown, what, why, tmp_path):
    r = _run(shown.text, tmp_path, 600)
    assert r.returncode == 0, f"{shown}\n{r.stderr[-3000:]}"


@pytest.mark.parametrize("shown, what, why", _of("python-c"), ids=_ids(_of("python-c")))
def test_each_python_c_line_runs_as_written(shown, what, why, tmp_path):
    r = _run(shown.text, tmp_path, 300)
    assert r.returncode == 0, f"{shown}\n{r.stderr[-3000:]}"


def _scripts(kinds: tuple[str, ...]):
    """Each script shown (by its path), with the options every command shown gives it."""
    found: dict[str, set[str]] = {}
    for s, what, _ in CHECKS:
        if what in kinds:
            words = _words(s.text)
            script = next(w for w in words if w.endswith(".py"))
            found.setdefault(script, set()).update(w.split("=")[0] for w in words[words.index(script) + 1:]
                                                   if w.startswith("--"))
    return sorted(found.items())


@pytest.mark.parametrize("script, options", _scripts(("help",)), ids=[s for s, _ in _scripts(("help",))])
def test_each_script_shown_answers_help_from_another_folder(script, options, tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    r = subprocess.run([sys.executable, str(ROOT / script), "--help"], capture_output=True, text=True, cwd=tmp_path,
                       env=env, timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert r.stdout.startswith("usage: "), r.stdout[:500]
    for option in options:
        assert re.search(rf"(^|\s|\[){re.escape(option)}\b", r.stdout), (option, r.stdout[:2000])
    assert not list(tmp_path.iterdir()), "--help wrote files"


@pytest.mark.parametrize("script, options", _scripts(("blender", "compiles")),
                         ids=[s for s, _ in _scripts(("blender", "compiles"))])
def test_each_script_run_elsewhere_exists_and_compiles(script, options, tmp_path):
    path = ROOT / script
    assert path.is_file(), script
    py_compile.compile(str(path), cfile=str(tmp_path / "compiled.pyc"), doraise=True)


@pytest.mark.parametrize("script", sorted((ROOT / "examples").glob("*.py")), ids=lambda p: p.name)
def test_every_example_answers_help_with_its_whole_summary(script, tmp_path):
    """``python examples/X.py --help`` (shown or not) answers from another folder without running the example, and
    its description holds the docstring's whole first paragraph, not a line cut mid-sentence."""
    import ast

    summary = " ".join(ast.get_docstring(ast.parse(script.read_text(encoding="utf-8"))).split("\n\n")[0].split())
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    r = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True, cwd=tmp_path, env=env,
                       timeout=300)
    assert r.returncode == 0, r.stderr[-3000:]
    assert r.stdout.startswith("usage: "), r.stdout[:500]
    assert summary in " ".join(r.stdout.split()), (summary, r.stdout[:1000])
    assert not list(tmp_path.iterdir()), "--help ran the example (it wrote files)"
