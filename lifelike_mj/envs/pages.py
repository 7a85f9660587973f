"""The environments' documentation pages, ``docs/envs/*.md``, rendered from the code so that they cannot drift from it.

Each environment module names its observation's and action's entries in a table of :class:`Entry` (name, unit,
meaning) that the environment itself uses (the names it puts in ``info["observation_names"]``, the 3D observation's
bounds); the prose (reward, starting state, episode end, arguments, version history) is the class's docstring. A
page is that docstring with the spaces filled in from a default instance (shape, dtype, each entry's bounds) and the
tables, plus what belongs to the page alone (a picture, an example, how it is checked: :data:`PAGES`). The
docstring gets the same tables, without the bounds (they depend on the arguments), through :func:`documented`.

Regenerate the pages after changing an environment::

    python -m lifelike_mj.envs.pages            # writes docs/envs/*.md
    python -m lifelike_mj.envs.pages --check    # exit status 1 if a page differs from what the code renders

``tests/envs/test_env_trust.py`` fails when a page in ``docs/envs/`` is not what :func:`render` gives now.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

#: The marker lines of an environment's docstring that :func:`documented` (and a page) replace by the tables.
OBSERVATIONS_MARK, ACTIONS_MARK = "{observations}", "{actions}"


@dataclass(frozen=True)
class Entry:
    """One entry of an observation or an action: its ``name``, its ``unit`` (SI; ``1`` for a pure number), what
    it means, and, where the environment's space takes it from here, its ``bound`` (the entry lies in
    ``[-bound, bound]``) and, for an action multiplied by a scale, that ``scale`` (in ``scale_unit``)."""

    name: str
    unit: str
    meaning: str
    bound: float | None = None
    scale: float | None = None
    scale_unit: str = ""


def names(entries: Sequence[Entry]) -> tuple[str, ...]:
    """The names of ``entries``, in order."""
    return tuple(e.name for e in entries)


def _number(v: float) -> str:
    return f"{float(v):.6g}"


def table(entries: Sequence[Entry], space: Any = None, scale_title: str = "") -> str:
    """A markdown table of ``entries``: index, name, unit, the bounds of each entry in the Gymnasium ``space`` (a
    ``Box``) when given, the scale (titled ``scale_title``) when the entries have one, and the meaning."""
    head = ["index", "name", "unit"]
    if space is not None:
        head += ["low", "high"]
    scaled = any(e.scale is not None for e in entries)
    if scaled:
        head.append(scale_title or "scale")
    head.append("meaning")
    rows = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for i, e in enumerate(entries):
        cells = [str(i), f"`{e.name}`", e.unit]
        if space is not None:
            cells += [_number(space.low[i]), _number(space.high[i])]
        if scaled:
            cells.append("" if e.scale is None else f"{_number(e.scale)} {e.scale_unit}".strip())
        cells.append(e.meaning)
        rows.append("| " + " | ".join(cells) + " |")
    return "\n".join(rows)


def box_text(space: Any) -> str:
    """A ``Box``'s shape, dtype and, where every entry shares them, bounds: ``Box(-1, 1, (9,), float64)``."""
    import numpy as np

    lo, hi = np.asarray(space.low), np.asarray(space.high)
    if lo.size and np.all(lo == lo.flat[0]) and np.all(hi == hi.flat[0]):
        return f"Box({_number(lo.flat[0])}, {_number(hi.flat[0])}, {tuple(space.shape)}, {space.dtype})"
    return f"Box({tuple(space.shape)}, {space.dtype})"


def documented(observations: Sequence[Entry], actions: Sequence[Entry], action_scale_title: str = ""):
    """Class decorator: fill the docstring's marker lines (:data:`OBSERVATIONS_MARK`, :data:`ACTIONS_MARK`) with the
    tables of ``observations`` and ``actions`` (no bounds: they depend on the arguments). The docstring as written
    is kept as ``__doc_template__`` for :func:`render`."""

    def decorate(cls):
        template = cls.__doc__ or ""
        cls.__doc_template__ = template
        cls.__doc__ = _fill(template, table(observations), table(actions, scale_title=action_scale_title))
        return cls

    return decorate


def _fill(template: str, observations: str, actions: str) -> str:
    out = []
    for line in template.splitlines():
        key = line.strip()
        if key in (OBSERVATIONS_MARK, ACTIONS_MARK):
            indent = line[: len(line) - len(line.lstrip())]
            out.extend(indent + t for t in (observations if key == OBSERVATIONS_MARK else actions).splitlines())
        else:
            out.append(line)
    return "\n".join(out)


# ---- docstrings into markdown -------------------------------------------------------------------------------------

_ROLE = re.compile(r":(?:class|func|meth|data|mod|attr|obj):`(~?)([^`]+)`")


def markdown(text: str) -> str:
    """A docstring's text as plain markdown: cross-references (``:class:`~a.B```) as code naming the object
    (``B``; the full path without the ``~``), double backticks as single ones, the common indentation removed."""
    import inspect

    text = inspect.cleandoc(text)
    text = _ROLE.sub(lambda m: f"`{m.group(2).rsplit('.', 1)[-1] if m.group(1) else m.group(2)}`", text)
    return re.sub(r"``([^`]+)``", r"`\1`", text)


def sections(doc: str) -> tuple[str, dict[str, str]]:
    """A docstring split at its ``## `` headings: the text before the first (its summary line and introduction),
    and each section's text by its heading."""
    parts = re.split(r"^## (.+)$", doc, flags=re.M)
    found = {parts[i].strip(): parts[i + 1].strip() for i in range(1, len(parts), 2)}
    return parts[0].strip(), found


# ---- the pages -------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Page:
    """A page of ``docs/envs/``: its environments (the first is the page's; the others are variants with a
    section each), the vector form's class, a picture and its caption, an example, the tests, and what the
    environment module's tables are called."""

    title: str
    env: str
    variants: tuple[str, ...]
    vector: str
    module: str
    picture: str
    caption: str
    example: str
    tests: str


#: The check that the documentation promises passes, run as written by ``tests/envs/test_env_trust.py`` (headless).
CHECK = '''import gymnasium as gym
from gymnasium.utils.env_checker import check_env

import lifelike_mj.envs  # registers the environments

check_env(gym.make("{env_id}").unwrapped)'''

PAGES = {
    "butterfly_pitch.md": Page(
        title="`lifelike_mj/ButterflyPitch-v0` and `ButterflyPitchWind-v0`",
        env="lifelike_mj.envs.butterfly:ButterflyPitchEnv",
        variants=("lifelike_mj.envs.butterfly:ButterflyPitchWindEnv",),
        vector="lifelike_mj.envs.vector:ButterflyPitchVectorEnv",
        module="lifelike_mj.envs.butterfly",
        picture="![The planar MuJoCo butterfly in settled flight, flown through the environment by the paper's network]"
                "(../figures/env_butterfly_pitch.png)",
        caption="*The environment's `rgb_array` frame on the MuJoCo backend after 5 s of flight, the shipped `ann_paper` "
                "network acting as the policy (`python docs/make_pictures.py`).*",
        example='''import gymnasium as gym
import lifelike_mj.envs                      # registers the environments (pip install "lifelike-mj[gym]")

env = gym.make("lifelike_mj/ButterflyPitch-v0")
obs, info = env.reset(seed=0)                # info["observation_names"]
obs, reward, terminated, truncated, info = env.step(env.action_space.sample())''',
        tests="`tests/envs/test_butterfly_env.py`, `tests/envs/test_vector_env.py`, "
              "`tests/envs/test_assess_through_env.py`, `tests/envs/test_env_trust.py`.",
    ),
    "butterfly_flight3d.md": Page(
        title="`lifelike_mj/ButterflyFlight3D-v0`",
        env="lifelike_mj.envs.butterfly3d:ButterflyFlight3DEnv",
        variants=(),
        vector="lifelike_mj.envs.butterfly3d:ButterflyFlight3DVectorEnv",
        module="lifelike_mj.envs.butterfly3d",
        picture="![A 3D butterfly in the middle of a 90° turn, flown through the environment by the shipped `designed` "
                "controller](../figures/env_butterfly_flight3d.png)",
        caption="*The environment's `rgb_array` frame 2.6 s into a 90° turn, the shipped `designed` controller flying as "
                "the baseline (`controller=\"designed\"`) under a residual policy of zeros (`python docs/make_pictures.py`).*",
        example='''import gymnasium as gym
import lifelike_mj.envs                      # registers the environments (pip install "lifelike-mj[gym]")

env = gym.make("lifelike_mj/ButterflyFlight3D-v0", task="course", every=12)
obs, info = env.reset(seed=0)                # info["observation_names"]
obs, reward, terminated, truncated, info = env.step(env.action_space.sample())''',
        tests="`tests/envs/test_flight3d_env.py` (Gymnasium's checker on every task; the evolved controllers' return "
              "equal to their `evolve3d` fitness to 1e-9; the vector form equal to single environments bit for bit; "
              "a network written out by `network_controller3d` flying the policy's rewards; `rgb_array`; bad "
              "arguments and actions refused in one sentence) and `tests/envs/test_env_trust.py`.",
    ),
}


def _load(ref: str):
    import importlib

    module, name = ref.split(":")
    return getattr(importlib.import_module(module), name)


def _template(cls) -> str:
    """A class's docstring as written (before :func:`documented` filled it in)."""
    return cls.__dict__.get("__doc_template__", cls.__doc__ or "")


def env_id(cls) -> str:
    """The registered id of an environment class."""
    from lifelike_mj.envs import ENVS

    ref = f"{cls.__module__}:{cls.__name__}"
    return next(k for k, v in ENVS.items() if v == ref)


def render(page: str) -> str:
    """The markdown of ``docs/envs/<page>`` (a key of :data:`PAGES`) as the code gives it now."""
    import importlib

    p = PAGES[page]
    cls = _load(p.env)
    mod = importlib.import_module(p.module)
    env = cls()
    try:
        obs_space, act_space = env.observation_space, env.action_space
    finally:
        env.close()
    intro, parts = sections(markdown(_template(cls)))
    title_line, _, intro = intro.partition("\n\n")
    actions = mod.ACTIONS[env.action_mode] if isinstance(mod.ACTIONS, dict) else mod.ACTIONS
    scale_title = getattr(mod, "ACTION_SCALE_TITLE", "")
    out = [f"<!-- Rendered from {p.module.replace('.', '/')}.py by `python -m lifelike_mj.envs.pages`: edit the code, "
           "not this file. -->", "", f"# {p.title}", "", p.picture, "", p.caption, "", " ".join(title_line.split()), "",
           intro.strip(), "", "```python", p.example, "```", ""]
    for heading, text in parts.items():
        if heading == "Version history":
            out += _variants(p) + _vector(p) + _checked(cls, p)
        out += [f"## {heading}", ""]
        if heading == "Action space":
            text = text.replace(ACTIONS_MARK, f"`{box_text(act_space)}` with the default arguments:\n\n"
                                + table(actions, act_space, scale_title))
        elif heading == "Observation space":
            text = text.replace(OBSERVATIONS_MARK, f"`{box_text(obs_space)}` with the default arguments:\n\n"
                                + table(mod.OBSERVATIONS, obs_space))
        out += [text, ""]
    return "\n".join(out).rstrip() + "\n"


def _variants(p: Page) -> list[str]:
    out = []
    for ref in p.variants:
        v = _load(ref)
        intro, parts = sections(markdown(_template(v)))
        first, _, rest = intro.partition("\n\n")
        out += [f"## `{env_id(v)}`", "", " ".join(first.split()), "", rest.strip(), ""]
    return out


def _vector(p: Page) -> list[str]:
    v = _load(p.vector)
    return ["## Vector form", "", f"`{v.__name__}`: " + markdown(v.__doc__), ""]


def _checked(cls, p: Page) -> list[str]:
    return ["## Checked", "", "Gymnasium's own checker passes as written here, also on a machine without a display "
            "(`rgb_array` draws offscreen; `human`, the MuJoCo viewer's window, is in `env.metadata[\"render_modes\"]` "
            "only where a window can open):", "", "```python", CHECK.format(env_id=env_id(cls)), "```", "",
            f"Tests: {p.tests}", ""]


def folder() -> Path:
    """The repository's ``docs/envs`` (the pages are written there)."""
    return Path(__file__).resolve().parents[2] / "docs" / "envs"


def main(argv: list[str] | None = None) -> int:
    """``python -m lifelike_mj.envs.pages [--check] [--out FOLDER]``: write every page (or, with ``--check``, say
    which differ from what the code renders, exit status 1 if any)."""
    ap = argparse.ArgumentParser(prog="python -m lifelike_mj.envs.pages",
                                 description="Render docs/envs/*.md from the environments' code.")
    ap.add_argument("--out", type=Path, default=None, help="the folder of the pages (default: the repository's docs/envs)")
    ap.add_argument("--check", action="store_true", help="write nothing; exit 1 if a page differs from the code's")
    args = ap.parse_args(argv)
    where = args.out or folder()
    stale = []
    for name in PAGES:
        path, text = where / name, render(name)
        if args.check:
            if not path.is_file() or path.read_text(encoding="utf-8") != text:
                stale.append(name)
        else:
            path.write_text(text, encoding="utf-8")
            print(f"wrote {path}")
    if stale:
        print(f"out of date (run python -m lifelike_mj.envs.pages): {', '.join(stale)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
