"""One self-contained web page that plays a run: the animated glTF (:mod:`lifelike_mj.export.gltf`) inside it
as base64, drawn by Google's ``<model-viewer>`` (vendored in ``web/``, with three.js inside; licences
beside it), with play/pause, a time scrub and the time. It needs no network and no server: open the file.

Controls: drag to orbit, scroll to zoom, the button or the space bar to play and pause, the slider to
scrub, and the camera: ``follow`` (a single creature: the view moves with it) or ``whole run`` (every body
at every frame in view; :mod:`lifelike_mj.export.cameras`). The page's ``<script id="provenance">`` holds
what made the run (strict JSON), as the glTF's ``asset.extras`` do.
"""

from __future__ import annotations

import base64
import html
import json
import math
from importlib import resources
from pathlib import Path

import numpy as np

from lifelike_mj.errors import UserError
from lifelike_mj.export.cameras import FOV_DEG, framing
from lifelike_mj.export.gltf import Z_UP_TO_Y_UP_MATRIX, build_gltf
from lifelike_mj.export.keys import DEFAULT_TOLERANCE
from lifelike_mj.export.poses import Poses
from lifelike_mj.io import atomic_path

#: The vendored viewer (npm ``@google/model-viewer``, its UMD build), inlined into each page.
VIEWER_JS = "model-viewer-umd.min.js"

_PAGE = """<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="{generator}">
<title>{title}</title>
<style>
  html, body {{ margin: 0; height: 100%; background: #f4f4f0; font: 14px system-ui, sans-serif; color: #222; }}
  model-viewer {{ width: 100%; height: calc(100% - 48px); --poster-color: transparent; }}
  #bar {{ display: flex; align-items: center; gap: 12px; height: 48px; padding: 0 12px; box-sizing: border-box; }}
  #scrub {{ flex: 1; }}
  #time {{ font-variant-numeric: tabular-nums; min-width: 9em; text-align: right; }}
  button {{ min-width: 5em; }}
</style>
<script>{viewer}</script>
</head>
<body>
<model-viewer id="run" src="data:model/gltf-binary;base64,{glb}" alt="{title}" camera-controls autoplay
  animation-name="{animation}" environment-image="neutral" shadow-intensity="0" interaction-prompt="none"
  field-of-view="{fov}deg" camera-orbit="{theta}deg {phi}deg {radius}m" camera-target="{target}"
  min-camera-orbit="auto auto 0.001m" max-camera-orbit="auto auto {far}m" min-field-of-view="1deg" max-field-of-view="120deg"
  interpolation-decay="30"></model-viewer>
<div id="bar">
  <button id="play" type="button" title="play or pause (space)">Pause</button>
  <select id="view" aria-label="camera"{single}>
    <option value="follow">follow</option>
    <option value="overview">whole run</option>
  </select>
  <input id="scrub" type="range" min="0" max="{duration}" step="any" value="0" aria-label="time">
  <span id="time">0.00 / {duration:.2f} s</span>
</div>
<script type="application/json" id="provenance">{provenance}</script>
<script type="application/json" id="framing">{framing}</script>
<script>
  const run = document.getElementById("run"), play = document.getElementById("play");
  const scrub = document.getElementById("scrub"), time = document.getElementById("time");
  const view = document.getElementById("view"), frame = JSON.parse(document.getElementById("framing").textContent);
  let dragging = false;
  function target(t) {{  // the followed body's place at time t (s), between its keyframes
    const p = frame.follow_path, n = p.length, u = Math.min(Math.max(t / frame.span_s, 0), 1) * (n - 1);
    const k = Math.min(Math.floor(u), n - 2), w = u - k;
    return [0, 1, 2].map((i) => p[k][i] + w * (p[k + 1][i] - p[k][i]));
  }}
  function aim() {{
    if (view.value === "follow" && frame.follow_path) {{
      const [x, y, z] = target(run.currentTime);
      run.cameraTarget = `${{x}}m ${{y}}m ${{z}}m`;
    }}
  }}
  view.addEventListener("change", () => {{
    if (view.value === "follow") {{
      run.cameraOrbit = `${{frame.theta}}deg ${{frame.phi}}deg ${{frame.follow_m}}m`;
    }} else {{
      run.cameraTarget = frame.centre.map((v) => v + "m").join(" ");
      run.cameraOrbit = `${{frame.theta}}deg ${{frame.phi}}deg ${{frame.overview_m}}m`;
    }}
    aim();
    run.jumpCameraToGoal();
  }});
  if (!frame.follow_path) view.value = "overview";
  function toggle() {{ if (run.paused) run.play(); else run.pause(); }}
  play.addEventListener("click", toggle);
  document.addEventListener("keydown", (e) => {{ if (e.code === "Space") {{ e.preventDefault(); toggle(); }} }});
  run.addEventListener("play", () => {{ play.textContent = "Pause"; }});
  run.addEventListener("pause", () => {{ play.textContent = "Play"; }});
  run.addEventListener("load", () => {{
    // a crowd's shared cycles (a flock's wing beat): each its own animation, looped on top of the run's; every
    // bird plays it at the phase its channels were stored in
    for (const name of frame.cycles) run.appendAnimation(name, {{repetitions: Infinity, fade: false, weight: 1}});
    scrub.max = run.duration;
    document.body.dataset.loaded = "yes";
  }});
  scrub.addEventListener("pointerdown", () => {{ dragging = true; }});
  scrub.addEventListener("pointerup", () => {{ dragging = false; }});
  scrub.addEventListener("input", () => {{ run.currentTime = Number(scrub.value); }});
  (function tick() {{
    if (!dragging) scrub.value = run.currentTime;
    aim();
    time.textContent = run.currentTime.toFixed(2) + " / " + (run.duration || {duration}).toFixed(2) + " s";
    requestAnimationFrame(tick);
  }})();
</script>
</body>
</html>
"""


def viewer_js() -> str:
    """The vendored ``<model-viewer>`` script (module docstring)."""
    return resources.files("lifelike_mj.export").joinpath("web", VIEWER_JS).read_text(encoding="utf-8")


def _inline(text: str) -> str:
    """Text safe inside a ``<script>`` element (no ``</script`` or ``<!--`` can end it early)."""
    return text.replace("</", "<\\/").replace("<!--", "<\\!--")


def build_html(poses: Poses, name: str = "lifelike-mj run", parameters: dict | None = None,
               rotations: str = "short", tolerance=DEFAULT_TOLERANCE, rigs: list | None = None) -> str:
    """The page (module docstring) of ``poses`` as text; :func:`write_html` writes it."""
    gl = build_gltf(poses, name, parameters, rotations, tolerance, rigs)
    f = framing(poses)
    follow = None if f.follow is None else {"path_m": poses.frames().position_m[:, f.follow],
                                            "distance_m": f.follow_m}
    return page(gl, name, {"centre_m": f.centre_m, "direction": f.direction, "overview_m": f.overview_m,
                           "span_s": float(poses.t_s[-1] - poses.t_s[0]), "follow": follow})


def page(gl, name: str, view: dict) -> str:
    """The page playing the glTF document ``gl``, framed by ``view``: ``centre_m``, ``direction`` (from what is
    looked at to the camera) and ``overview_m`` (MuJoCo's world, m), ``span_s`` (s), and ``follow`` (None, or
    ``path_m``: the followed creature's place at each playback frame, and ``distance_m``)."""
    y_up = Z_UP_TO_Y_UP_MATRIX
    d = y_up @ np.asarray(view["direction"], dtype=float)  # model-viewer's orbit: theta about +Y from +Z, phi from +Y
    theta, phi = math.degrees(math.atan2(d[0], d[2])), math.degrees(math.acos(max(-1.0, min(1.0, d[1]))))
    follow = view["follow"]
    centre = y_up @ np.asarray(view["centre_m"], dtype=float)
    overview_m = float(view["overview_m"])
    frame = {"theta": round(theta, 3), "phi": round(phi, 3), "overview_m": overview_m,
             "follow_m": float(follow["distance_m"]) if follow else 0.0,
             "centre": [float(v) for v in centre], "span_s": float(view["span_s"]),
             "follow_path": (np.round(np.asarray(follow["path_m"]) @ y_up.T, 5).tolist() if follow else None),
             "cycles": [a.name for a in gl.animations if "lifelike_mj_cycle" in (a.extras or {})]}
    glb = b"".join(gl.save_to_bytes())
    prov = json.dumps(gl.asset.extras, allow_nan=False)
    target = (y_up @ np.asarray(follow["path_m"][0], dtype=float)) if follow else centre
    return _PAGE.format(generator=html.escape(gl.asset.generator), title=html.escape(name),
                        viewer=_inline(viewer_js()), glb=base64.b64encode(glb).decode("ascii"),
                        animation=html.escape(next((a.name for a in gl.animations if a.name not in frame["cycles"]), "")),
                        duration=frame["span_s"], provenance=_inline(prov),
                        framing=_inline(json.dumps(frame, allow_nan=False)), fov=FOV_DEG, theta=frame["theta"],
                        phi=frame["phi"], radius=frame["follow_m"] if follow else overview_m,
                        target=" ".join(f"{v}m" for v in target), far=10.0 * overview_m,
                        single="" if follow else " hidden")


def write_html(poses: Poses, path: str | Path, name: str = "lifelike-mj run", parameters: dict | None = None,
               rotations: str = "short", tolerance=DEFAULT_TOLERANCE, rigs: list | None = None) -> Path:
    """Write the page of ``poses`` (module docstring) to ``path`` (``.html``), atomically. Returns the path."""
    path = Path(path)
    if path.suffix.lower() != ".html":
        raise UserError(f"a web page ends in .html, got {path.name!r}.")
    text = build_html(poses, name, parameters, rotations, tolerance, rigs)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path
