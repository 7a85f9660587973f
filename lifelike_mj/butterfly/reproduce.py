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


def _yesno(flag: bool) -> str:
    return "yes" if flag else "no"


def _band(v: dict, digits: int = 2) -> str:
    """Settled altitude band ``[min, max] m`` of a flight's numbers."""
    return f"[{v['settled_altitude_min_m']:+.{digits}f}, {v['settled_altitude_max_m']:+.{digits}f}] m"


def _ann_section(out: Path, params: ButterflyParams) -> tuple[str, dict]:
    """E6-E11 with the shipped ``ann_paper`` (and ``ann_robust`` beside it): figures and a table."""
    from lifelike_mj.butterfly import ann_experiments as ax
    from lifelike_mj.viz import ann_figures as af

    paper_ctrl = controllers.load("ann_paper")
    robust = controllers.load("ann_robust") if "ann_robust" in controllers.builtin_names() else None
    e6 = ax.e6_level(paper_ctrl, params=params)
    e7 = ax.e7_from_above(paper_ctrl, params=params)
    e8 = ax.e8_glide(paper_ctrl, params=params)
    e9 = ax.e9_from_below(paper_ctrl, params=params)
    e10 = ax.e10_winds(paper_ctrl, params=params)
    maps = {k: ax.e11_windmap(paper_ctrl, k, params=params) for k in ("relative", "ground")}
    if e6.fitness_history:
        af.fig7_fitness(e6.fitness_history, out / "fig7_fitness.png", label="ann_paper (rcga, seed "
                        f"{paper_ctrl.provenance.get('seed')})")
    af.fig8_flight(e6, out / "fig8_flight.png")
    af.fig9_phi(e6, out / "fig9_phi.png")
    af.fig11_from_above(e7, out / "fig11_from_above.png")
    af.fig12_sink(e8, out / "fig12_sink.png")
    af.fig13_from_below(e9, out / "fig13_from_below.png")
    af.fig14_15_winds(e10, out / "fig14_15_winds.png")
    af.fig_windmap([maps["relative"], maps["ground"]], out / "fig15_windmap.png",
                   titles=["ann_paper, air-relative inputs", "ann_paper, ground-velocity inputs"])
    n6, n7 = e6.numbers, e7.flights["+10 m"]
    rows = [
        ("E6 initial drop from 0 m", "≈0.5 m", f"{n6['initial_drop_m']:.3f} m"),
        ("E6 settled altitude, last 10 s", "holds 0 m", _band(n6, 3)),
        ("E6 settled forward speed", "—", f"{n6['settled_forward_speed_cm_s']:.1f} cm/s"),
        ("E6 time to reach z = 20 m", "≈6.9 s", f"{e6.time_to_z20_s:.2f} s" if e6.time_to_z20_s else "never"),
        ("E6 cycles whose max phi is 30°", "every cycle",
         f"{e6.to_dict()['cycles_with_phi_max_30deg']} of {len(e6.phi_max_per_cycle_deg)}"),
        ("E6 correlation of per-cycle min phi with altitude (first 3 s)", "inverse relation",
         f"{e6.corr_phi_min_altitude:+.2f}"),
        ("E7 from +10 m: settled altitude", "≈0 m and holds", _band(n7, 3)),
        ("E8 max sink speed, glide / flapping", "≈2×", f"{e8.max_sink_gliding_m_s:.2f} / {e8.max_sink_flapping_m_s:.2f} m/s"
         f" = {e8.ratio:.2f}×"),
    ]
    for k, v in e9.flights.items():
        rows.append((f"E9 from {k}: reaches 0 m (±0.5 m)?", "no", f"{_yesno(v['reaches_target'])}; final "
                     f"{v['final_altitude_m']:+.2f} m"))
    paper_e10 = {"front (2,0)": "holds ≈0 m (relative); climbs at once (ground)", "above (0,2)": "level at an offset",
                 "behind (-2,0)": "crashes", "below (0,-2)": "level at an offset"}
    for inputs, flights in e10.flights.items():
        for w, v in flights.items():
            rows.append((f"E10 wind from {w}, {inputs} inputs", paper_e10[w],
                         f"settled {_band(v)}, {v['settled_forward_speed_cm_s']:.0f} cm/s"))
    for k, m in maps.items():
        q = m.quadrants()
        paper_e11 = {"relative": "weak to tail + from-above wind",
                     "ground": "more robust than relative inputs to tail + from-below wind"}
        rows.append((f"E11 wind map ({k} inputs), cells passing", paper_e11[k],
                     f"{m.pass_cells}/{m.total_cells}; tail+above {100 * q['tail+from_above']:.0f} %, "
                     f"tail+below {100 * q['tail+from_below']:.0f} %"))
    data = {"e6": e6.to_dict(), "e7": e7.to_dict(), "e8": e8.to_dict(), "e9": e9.to_dict(), "e10": e10.to_dict(),
            "e11": {k: m.to_dict() for k, m in maps.items()}}
    body = ["Controller `ann_paper` (evolved by the paper's RCGA at full scale; its provenance is in the file). "
            "Paper backend, RK4, dt = 1/1200 s, flap 10 Hz over [-60, 75]°, 20 s.", "",
            "| experiment | paper | ours |", "|---|---|---|"]
    body += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    body += [""] + [f"![{n}]({n}.png)" for n in ("fig7_fitness", "fig8_flight", "fig9_phi", "fig11_from_above",
                                                 "fig12_sink", "fig13_from_below", "fig14_15_winds", "fig15_windmap")
                    if (out / f"{n}.png").exists()]
    if robust is not None:
        rfb = ax.e9_from_below(robust, params=params, starts=(-10.0,))
        rb = {"from -10 m": rfb.flights["-10 m"],
              "still air": ax.e6_level(robust, params=params).numbers}
        tail = ax.e10_winds(robust, params=params).flights
        rmaps = {k: ax.e11_windmap(robust, k, params=params) for k in ("relative", "ground")}
        af.fig_windmap([maps["relative"], rmaps["relative"], maps["ground"], rmaps["ground"]],
                       out / "fig_windmap_paper_vs_robust.png",
                       titles=["ann_paper, relative", "ann_robust, relative", "ann_paper, ground", "ann_robust, ground"])
        trs = {"ann_paper from -10 m": e9.trajectories["-10 m"],
               "ann_robust from -10 m": rfb.trajectories["-10 m"]}
        af.fig_compare_starts(trs, out / "fig_robust_from_below.png", "ann_paper vs ann_robust from -10 m")
        tw = tail[robust.parameters["inputs"]]["behind (-2,0)"]
        pw = e10.flights[paper_ctrl.parameters["inputs"]]["behind (-2,0)"]
        r10 = rb["from -10 m"]
        body += ["", "### ann_robust (beyond the paper: trained over start altitudes and winds)", "",
                 "| case | ann_paper | ann_robust |", "|---|---|---|",
                 f"| from -10 m: reaches ±0.5 m of 0 within 20 s | {_yesno(e9.flights['-10 m']['reaches_target'])} | "
                 f"{_yesno(r10['reaches_target'])} (first within 0.5 m at {r10['time_to_within_0_5m_s']:.1f} s) |",
                 f"| 2 m/s tail wind: settled altitude | {_band(pw)} | {_band(tw)}, drop {tw['initial_drop_m']:.2f} m |",
                 f"| still air: settled altitude | {_band(n6, 3)} | {_band(rb['still air'], 3)} |",
                 f"| wind map cells passing, relative inputs | {maps['relative'].pass_cells} | {rmaps['relative'].pass_cells} |",
                 f"| wind map cells passing, ground inputs | {maps['ground'].pass_cells} | {rmaps['ground'].pass_cells} |",
                 "", "![windmaps](fig_windmap_paper_vs_robust.png)", "", "![from below](fig_robust_from_below.png)"]
        data["robust"] = {"from_-10m": rb["from -10 m"], "still_air": rb["still air"],
                          "tail_wind": tw, "e11": {k: m.to_dict() for k, m in rmaps.items()}}
    return "\n".join(body) + "\n", data


def reproduce_all(out: Path, params: ButterflyParams | None = None) -> dict:
    """Run everything and write ``report.md``, ``results.json`` and the figures into ``out``."""
    p = params or ButterflyParams()
    out.mkdir(parents=True, exist_ok=True)
    print("comparison runs (paper backend vs MuJoCo) ...", file=sys.stderr)
    cmp_body, cmp_data = _compare_section(out, p)
    print("snapshots ...", file=sys.stderr)
    snap_body = _snapshot_section(out, p)
    print("E6-E11 with the evolved controllers ...", file=sys.stderr)
    ann_body, ann_data = _ann_section(out, p)
    results = report.reproduce(out, p, extra_sections=[("Comparison of the two backends", cmp_body),
                                                       ("Snapshots (Fig. 10 style)", snap_body),
                                                       ("The evolved network: E6-E11 (Oe 2010 sections 6-7)", ann_body)])
    results["compare"] = cmp_data
    results["ann"] = ann_data
    write_json(out / "results.json", results)
    return results
