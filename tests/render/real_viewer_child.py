"""Child process of ``test_real_viewer.py``: ``lifelike-mj view CREATURE ARGS`` in MuJoCo's real desktop viewer,
printing one JSON line per event on stdout:

* ``{"event": "ready", "options": ...}`` once the window shows its first frame;
* ``{"event": "control", "label": ..., "options": ...}`` after each scene key's action ran.

``options`` is what MuJoCo's own shortcuts toggle and the scene must leave alone: the viewer's ``mjvOption``
(every flag and group) and its camera. With ``--freeze`` the stepper does not move (its step counter does, so
``--duration`` still ends the view): two screenshots then differ only where a key changed what is drawn.
"""

from __future__ import annotations

import json
import sys

from lifelike_mj.render import viewer

_handles: list = []
_launch = viewer.launch_viewer


def _capture(*args, **kwargs):
    h = _launch(*args, **kwargs)
    _handles.append(h)
    return h


def options() -> dict:
    """The viewer's options now (read without its lock: the scene's loop holds it while a control runs)."""
    h = _handles[0]
    o, c = h.opt, h.cam
    return {"flags": o.flags.tolist(), "geomgroup": o.geomgroup.tolist(), "sitegroup": o.sitegroup.tolist(),
            "jointgroup": o.jointgroup.tolist(), "tendongroup": o.tendongroup.tolist(),
            "actuatorgroup": o.actuatorgroup.tolist(), "flexgroup": o.flexgroup.tolist(),
            "skingroup": o.skingroup.tolist(), "frame": int(o.frame), "label": int(o.label),
            "camera": [int(c.type), int(c.trackbodyid), int(c.fixedcamid)]}


def say(event: str, **data) -> None:
    print(json.dumps({"event": event, **data}), flush=True)


class Frozen:
    """``stepper`` that does not move: ``step(n)`` only counts."""

    def __init__(self, stepper) -> None:
        self._stepper, self._steps = stepper, int(stepper.steps)

    def __getattr__(self, name: str):
        return getattr(self._stepper, name)

    @property
    def steps(self) -> int:
        return self._steps

    def step(self, n: int = 1) -> None:
        self._steps += int(n)


def main() -> int:
    creature, *args = sys.argv[1:]
    freeze = "--freeze" in args
    args = [a for a in args if a != "--freeze"]
    viewer.launch_viewer = _capture
    view = viewer.view

    def watched_view(stepper, steps_per_s, end_step=None, setup=None, web=None, controls=()):
        def reporting(c):
            def act():
                c.act()
                say("control", label=c.label, options=options())
            return act

        class Ready:
            """Says ``ready`` at the first frame drawn (the second sync: the first comes before the window's)."""

            syncs = 0

        target = Frozen(stepper) if freeze else stepper
        sync = target.sync

        def first_sync():
            sync()
            Ready.syncs += 1
            if Ready.syncs == 2:
                say("ready", options=options())

        if freeze:
            target.sync = first_sync
        else:
            stepper.sync = first_sync
        wrapped = [viewer.Control(c.key, c.label, reporting(c)) for c in controls]
        return view(target, steps_per_s, end_step, setup, web, wrapped)

    import importlib

    for name in ("butterfly.render", "butterfly.flight3d.view", "fish.render", "boids.render"):
        importlib.import_module(f"lifelike_mj.{name}").view = watched_view
    from lifelike_mj.cli import main as cli

    return cli(["view", creature, *args])


if __name__ == "__main__":
    sys.exit(main())
