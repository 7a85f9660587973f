"""``lifelike-mj reproduce butterfly``: E1-E5, the two-backend comparison, and the snapshots."""

from __future__ import annotations

import sys
from pathlib import Path

from lifelike_mj.butterfly import controllers, report
from lifelike_mj.butterfly.compare import compare
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError
from lifelike_mj.io import write_json


def _compare_section(out: Path, params: ButterflyParams) -> tuple[str, list[dict]]:
    from lifelike_mj.viz.flight import fig_compare

    rule = controllers.load("simple_rule")
    results = [compare(rule, cfg, params) for cfg in ("paper", "rich")]
    fig_compare(results, out / "fig_compare_backends.png")
    rows = ["| configuration | wing force | max altitude diff | max forward diff | paper's excursion | note |",
            "|---|---|---|---|---|---|"]
    notes = {
        "paper": "light wings, planar joints, pitch set per step: must agree (< 1 % of the excursion or < 2 cm)",
        "rich": "free body with attitude servo, 0.016 g wings, strip integration: the cost of the paper's "
                "simplifications (eq. 7 ignores the vertical speed and theta)",
    }
    for r in results:
        rows.append(f"| {r.config} | {r.force_mode} | {100 * r.max_altitude_diff_m:.2f} cm "
                    f"({100 * r.altitude_diff_fraction:.2f} %) | {100 * r.max_forward_diff_m:.2f} cm | "
                    f"{r.max_altitude_excursion_m:.2f} m | {notes[r.config]} |")
    body = ("Simple rule at the paper's 12.77 deg, flap [-90, 90] deg, RK4, dt = 1/1200 s, 20 s.\n\n"
            + "\n".join(rows) + "\n\n![comparison](fig_compare_backends.png)\n")
    return body, [r.to_dict() for r in results]


def _snapshot_section(out: Path, params: ButterflyParams) -> str:
    try:
        from lifelike_mj.viz.video import snapshot_figure

        snapshot_figure(out / "fig10_snapshots.png", controllers.load("simple_rule"), params)
    except (UserError, ImportError, RuntimeError) as exc:
        return f"Snapshots not rendered on this machine: {exc}\n"
    return ("The MuJoCo model in settled flight, one frame every 0.025 s (the paper's Fig. 10 shows the "
            "evolved controller; here the simple rule).\n\n![snapshots](fig10_snapshots.png)\n")


def reproduce_all(out: Path, params: ButterflyParams | None = None) -> dict:
    """Run everything and write ``report.md``, ``results.json`` and the figures into ``out``."""
    p = params or ButterflyParams()
    out.mkdir(parents=True, exist_ok=True)
    print("comparison runs (paper backend vs MuJoCo) ...", file=sys.stderr)
    cmp_body, cmp_data = _compare_section(out, p)
    print("snapshots ...", file=sys.stderr)
    snap_body = _snapshot_section(out, p)
    results = report.reproduce(out, p, extra_sections=[("Comparison of the two backends", cmp_body),
                                                       ("Snapshots (Fig. 10 style)", snap_body)])
    results["compare"] = cmp_data
    write_json(out / "results.json", results)
    return results
