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


def test_the_contracts_can_fail(tmp_path, monkeypatch):
    """A creature that imports another breaks a contract (the checker is not vacuous)."""
    cli = pytest.importorskip("importlinter.cli")
    import shutil

    copy = tmp_path / "lifelike_mj"
    shutil.copytree(PKG, copy, ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "fish" / "intruder.py").write_text("from lifelike_mj.butterfly import flight\n")
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
