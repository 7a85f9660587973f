"""The API reference builds from the docstrings (pdoc), and documents the public names."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


def test_api_reference_builds(tmp_path):
    pytest.importorskip("pdoc")
    env = dict(os.environ, LIFELIKE_MJ_EAGER="1", MUJOCO_GL=os.environ.get("MUJOCO_GL") or "egl")
    r = subprocess.run([sys.executable, "-m", "pdoc", "lifelike_mj", "-o", str(tmp_path)], capture_output=True,
                       text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "Warn" not in r.stderr, r.stderr[-3000:]
    pages = {p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*.html")}
    for page in ("lifelike_mj.html", "lifelike_mj/butterfly.html", "lifelike_mj/fish.html", "lifelike_mj/boids.html",
                 "lifelike_mj/evolve.html", "lifelike_mj/render.html", "lifelike_mj/stepper.html",
                 "lifelike_mj/butterfly/sim.html", "lifelike_mj/butterfly/flight.html"):
        assert page in pages, page
    # every public module (no part of its path private; the command line is documented by --help) has a page
    from pathlib import Path

    import lifelike_mj

    root = Path(lifelike_mj.__file__).parent
    missing = []
    for f in sorted(root.rglob("*.py")):
        parts = f.relative_to(root.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") for p in parts) or "cli" in parts:
            continue
        if "/".join(parts) + ".html" not in pages:
            missing.append(".".join(parts))
    assert not missing, f"no API page for {missing}"
    flight = (tmp_path / "lifelike_mj" / "butterfly.html").read_text()
    assert "PitchObservation" in flight and "Flight" in flight and "Oe, Suzuki, Yamamoto" in flight
