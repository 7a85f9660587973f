"""The layers are executable: the import-linter contracts in pyproject.toml hold, and no creature
reaches into the rendering package's (or another layer's) private names."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "lifelike_mj"


def test_import_linter_contracts_are_kept(monkeypatch):
    cli = pytest.importorskip("importlinter.cli")
    monkeypatch.chdir(ROOT)
    assert cli.lint_imports(config_filename=str(ROOT / "pyproject.toml"), no_cache=True) == 0


INTRUDERS = {
    "a creature imports another": ("fish/intruder.py", "from lifelike_mj.butterfly import flight\n"),
    "the planar butterfly imports the 3D slice": ("butterfly/sim.py", "from lifelike_mj.butterfly.flight3d import loop\n"),
    "the 3D kinematics import the 3D stepper": ("butterfly/flight3d/kinematics.py",
                                                "from lifelike_mj.butterfly.flight3d import flight\n"),
}


@pytest.mark.parametrize("case", sorted(INTRUDERS))
def test_the_contracts_can_fail(tmp_path, monkeypatch, case):
    """An import against the layers breaks a contract (the checker is not vacuous)."""
    cli = pytest.importorskip("importlinter.cli")
    import shutil

    copy = tmp_path / "lifelike_mj"
    shutil.copytree(PKG, copy, ignore=shutil.ignore_patterns("__pycache__"))
    where, line = INTRUDERS[case]
    target = copy / where
    target.write_text((target.read_text() if target.exists() else "") + line)
    (tmp_path / "pyproject.toml").write_text((ROOT / "pyproject.toml").read_text())
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    import sys

    for name in [m for m in sys.modules if m == "lifelike_mj" or m.startswith("lifelike_mj.")]:
        monkeypatch.delitem(sys.modules, name)
    assert cli.lint_imports(config_filename=str(tmp_path / "pyproject.toml"), no_cache=True) != 0


def test_no_module_imports_private_names_of_another_package():
    import ast

    bad = []
    for path in PKG.rglob("*.py"):
        own = ".".join(path.relative_to(ROOT).with_suffix("").parts[:2])
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("lifelike_mj"):
                if node.module.startswith(own):  # a package's own private names are its business
                    continue
                bad += [f"{path.relative_to(ROOT)}: {node.module}.{a.name}" for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")]
    assert not bad, bad


def _graph():
    grimp = pytest.importorskip("grimp")
    return grimp.build_graph("lifelike_mj", cache_dir=None)


def _circles(graph) -> list[list[str]]:
    """The import circles between the package's modules (strongly connected components of more than one module,
    counting imports inside functions too)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:  # Tarjan's algorithm
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.find_modules_directly_imported_by(v):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for m in sorted(graph.modules):
        if m not in index:
            visit(m)
    return out


def test_no_import_circle_between_the_packages_files():
    graph = _graph()
    assert _circles(graph) == []
    graph.add_import(importer="lifelike_mj.boids.engine", imported="lifelike_mj.boids.sim")  # what there was
    assert ["lifelike_mj.boids.engine", "lifelike_mj.boids.presets", "lifelike_mj.boids.sim"] in _circles(graph)


def test_every_planar_butterfly_module_is_under_the_planar_contract():
    """A new planar module is named in the contract that keeps it off the 3D slice."""
    tomllib = pytest.importorskip("tomllib")  # Python 3.11 on

    contracts = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
    (planar,) = [c for c in contracts if c.get("forbidden_modules") == ["lifelike_mj.butterfly.flight3d"]]
    mods = {m for m in _graph().modules if m.startswith("lifelike_mj.butterfly.")
            and not m.startswith("lifelike_mj.butterfly.flight3d") and m.count(".") == 2}
    assert mods == set(planar["source_modules"])
