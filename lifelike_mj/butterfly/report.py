"""``lifelike-mj reproduce butterfly``: the butterfly paper's experiments into a folder.

:func:`reproduce` runs everything: E1-E5 (:func:`report_e1_e5`), the comparison of the two
backends, the snapshots of Fig. 10, and E6-E11 with the shipped evolved networks, and writes the
figures, ``results.json`` and ``report.md``. :func:`report_e1_e5` runs
:mod:`lifelike_mj.butterfly.experiments` E1-E5 (Oe 2010 eq. 1-11, sections 4-5, Fig. 3-5), draws the
figures with :mod:`lifelike_mj.butterfly.figures`, and writes ``results.json`` (every experiment's
``to_dict()``) and ``report.md`` (a table "experiment | paper | ours | note" and the figures).
Every file is written atomically.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict
from pathlib import Path

from lifelike_mj.butterfly import controllers, experiments, figures
from lifelike_mj.butterfly.compare import compare
from lifelike_mj.butterfly.params import ButterflyParams
from lifelike_mj.errors import UserError
from lifelike_mj.io import dumps, write_json, write_text
from lifelike_mj.progress import Stages
from lifelike_mj.render.plot import markdown_figure

FIGURES = {
    "fig3": "fig3_forces.png",
    "speed_limit": "fig_speed_limit.png",
    "fig4": "fig4_trim.png",
    "fig5": "fig5_timestep.png",
}


def _fmt(x: float, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return str(x)
    return f"{x:.{digits}g}"


def _dt(dt_s: float) -> str:
    """A time step as ``1/n`` when it is one, else in seconds."""
    n = 1.0 / dt_s
    return f"1/{round(n)}" if abs(n - round(n)) < 1e-6 * n else _fmt(dt_s)


def _table(results: dict) -> list[tuple[str, str, str, str]]:
    """Rows ``(experiment, paper, ours, note)`` for every number the paper states."""
    e1, e2, e3, sweep, e4, e5 = (results[k] for k in ("e1", "e2", "e3", "e3_vs_area", "e4", "e5"))
    conv = " / ".join(f"{_fmt(c['max_rel_error'], 2)}" for c in e1["midpoint_convergence"])
    ns = " / ".join(str(c["n_strips"]) for c in e1["midpoint_convergence"])
    rows = [
        ("E1 closed forms eq. 4, 6 vs strip integration (max rel. error)", "exact",
         _fmt(e1["closed_form_max_rel_error"], 2), "64 strips, 3-point Gauss rule per strip"),
        (f"E1 midpoint strip sum, n = {ns} (max rel. error)", "—", conv, "converges as O(n^-2)"),
        ("E1 best velocity efficiency F/ω² (section 4.1)", "planform 2 (Fig. 2 centre)",
         f"planform {e1['best_velocity_efficiency_planform']}", "the paper adopts planform 2"),
        ("E1 best torque efficiency F/τ (section 4.1)", "planform 1 (Fig. 2 left)",
         f"planform {e1['best_torque_efficiency_planform']}", ""),
    ]
    by = {}
    for c in e2["curves"]:
        by.setdefault(c["v_z_m_s"], []).append(c)
    speeds = sorted(by)
    fzmax = [1e3 * max(max(c["F_z_N"]) for c in by[v]) for v in speeds]
    fyrng = [(1e3 * min(min(c["F_y_N"]) for c in by[v]), 1e3 * max(max(c["F_y_N"]) for c in by[v])) for v in speeds]
    vs = ", ".join(f"{v:g}" for v in speeds)
    rows += [
        (f"E2 Fig. 3: max over φ of F_z (mN), v_z = {vs} m/s", "decreases as v_z grows",
         " / ".join(_fmt(f, 3) for f in fzmax), "both strokes, ω = ±62.8 rad/s, θ = 0"),
        (f"E2 Fig. 3: range of F_y (mN), v_z = {vs} m/s", "widens as v_z grows",
         " / ".join(f"[{_fmt(a, 3)}, {_fmt(b, 3)}]" for a, b in fyrng), ""),
        (f"E3 speed limit (cm/s), A_b = {_fmt(e3['body_area_cm2'])} cm² (this run)", "380",
         str(e3["speed_limit_cm_s"]), f"continuous solution {_fmt(100 * e3['closed_form_m_s'], 5)} cm/s"),
    ]
    if abs(e3["body_area_cm2"] - 1.0) > 1e-12:
        rows.append(("E3 speed limit (cm/s), A_b = 1.0 cm²", "380", str(sweep["limit_at_1cm2_cm_s"]),
                     "A_b is not stated in the paper; 1.0 cm² (the default) fits E4"))
    rows += [
        ("E3 speed limit (cm/s), A_b = 1.53 cm²", "380", str(sweep["limit_at_1_53cm2_cm_s"]),
         f"380 cm/s holds up to A_b = {_fmt(sweep['area_at_380_cm2'], 5)} cm²"),
        ("E4 level-flight upstroke pitch φ_up (deg)", "12.77", _fmt(e4["phi_up_level_deg"], 6),
         f"root of the settled climb rate (last 10 s), {e4['backend']} backend, dt = {_dt(e4['dt_s'])} s"),
        ("E4 settled forward speed (cm/s)", "340", _fmt(e4["mean_forward_speed_cm_s"], 4),
         "mean v_z over the last 10 s"),
        ("E4 altitude ripple (cm)", "≈5.3", _fmt(e4["ripple_cm"], 3), "mean per-flap-cycle peak-to-peak, last 10 s"),
        ("E4 initial drop (m)", "≈3", _fmt(e4["initial_drop_m"], 3), f"A_b = {_fmt(e4['body_area_cm2'])} cm²"),
        ("E4 final altitude (m) / settled climb rate (cm/s) at the level angle", "level flight",
         f"{_fmt(e4['final_altitude_m'], 4)} / {_fmt(e4['settled_climb_rate_cm_s'], 2)}", ""),
        (f"E4 φ_up = level − 0.5° ({_fmt(e4['below']['phi_up_deg'], 5)}°): final altitude (m) / climb rate (cm/s)",
         "descends", f"{_fmt(e4['below']['final_altitude_m'], 4)} / {_fmt(e4['below']['settled_climb_rate_cm_s'], 4)}",
         "descends" if e4["below"]["settled_climb_rate_cm_s"] < 0 else "does NOT descend"),
        (f"E4 φ_up = level + 0.5° ({_fmt(e4['above']['phi_up_deg'], 5)}°): final altitude (m) / climb rate (cm/s)",
         "climbs", f"{_fmt(e4['above']['final_altitude_m'], 4)} / {_fmt(e4['above']['settled_climb_rate_cm_s'], 4)}",
         "climbs" if e4["above"]["settled_climb_rate_cm_s"] > 0 else "does NOT climb"),
    ]
    paper_rel = e5["paper"]["rel_error"]
    for label, alt in e5["altitude_20s_m"].items():
        paper_alt = "lower than the others" if label == "1/120" else "≈15–16"
        rows.append((f"E5 altitude at 20 s (m), dt = {label} s, φ_up = {_fmt(e5['phi_up_deg'])}°", paper_alt,
                     _fmt(alt, 6), "reference run" if label == "1/12000" else ""))
    for label, err in e5["rel_error"].items():
        if label == "1/12000":
            continue
        paper_err = f"≈{_fmt(100 * paper_rel[label])} %" if label in paper_rel else "—"
        rows.append((f"E5 relative altitude error at 20 s, dt = {label} s", paper_err, f"{_fmt(100 * err, 3)} %",
                     "|y(20) − y_ref(20)| / |y_ref(20)|, reference dt = 1/12000 s"))
    rows.append(("E5 error ratio, dt 1/360 vs 1/1200 (dt ×3)", "≈10", _fmt(e5["error_ratio_per_3x_dt"], 3),
                 "RK4 alone would give 3^4 = 81"))
    return rows


def _markdown(results: dict, extra_sections: list[tuple[str, str]] | None) -> str:
    p = results["params"]
    lines = [
        "# Butterfly (Oe, Suzuki, Yamamoto, Furukawa 2010): experiments E1–E11, paper vs ours",
        "",
        f"Backend for E4–E5: `{results['backend']}`. Constants: m = {_fmt(1e3 * p['mass_kg'])} g, "
        f"L = {_fmt(1e2 * p['span_m'])} cm, W = {_fmt(1e2 * p['width_m'])} cm, ρ = {_fmt(p['rho'])} kg/m³, "
        f"C_d = {_fmt(p['cd'])}, A_b = {_fmt(1e4 * p['body_area_m2'])} cm², g = {_fmt(p['gravity'])} m/s².",
        "",
        "| experiment | paper | ours | note |",
        "|---|---|---|---|",
    ]
    for row in _table(results):
        lines.append("| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |")
    lines += ["", "## Figures of E1–E5", ""]
    captions = {
        "fig3": "Oe 2010 Fig. 3 — F_y and F_z against φ for v_z = 0, 2, 4 m/s, upstroke and downstroke (E2).",
        "speed_limit": "Oe 2010 section 4.3 — the forward-speed limit against the body area A_b (E3).",
        "fig4": "Oe 2010 Fig. 4 — flight by the simple rule at the level angle and ±0.5° (E4).",
        "fig5": "Oe 2010 Fig. 5 — flights and altitude differences for four time steps (E5).",
    }
    for key, name in FIGURES.items():
        lines += [markdown_figure(name, captions[key]), ""]
    for title, body in extra_sections or []:
        lines += [f"## {title}", "", body.rstrip(), ""]
    return "\n".join(lines).rstrip() + "\n"


def report_e1_e5(
    out_dir: Path,
    params: ButterflyParams | None = None,
    backend: str = "paper",
    extra_sections: list[tuple[str, str]] | None = None,
    progress: bool = True,
    stages: Stages | None = None,
) -> dict:
    """Run E1-E5 (Oe 2010 eq. 4-11, Fig. 3-5), write the figures, ``results.json`` and
    ``report.md`` into ``out_dir``, and return the results (the JSON data).

    E1-E3 are analytic (no backend); E4 and E5 fly on ``backend`` at the paper's settings
    (RK4, 20 s; dt = 1/12000 s for E4, four steps for E5). ``extra_sections`` are appended to
    the Markdown as ``## title`` and body. Progress (a bar per stage, then its duration) goes to stderr
    when ``progress``; ``stages`` continues the numbering of a larger job.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    p = params or ButterflyParams()

    st = stages if stages is not None else Stages("reproduce butterfly", 4, progress)
    t0 = time.perf_counter()
    with st.next("E1-E3: closed forms, Fig. 3 forces, speed limit"):
        e1 = experiments.e1_closed_forms(p)
        e2 = experiments.e2_fig3(p)
        e3 = experiments.e3_speed_limit(p)
        sweep = experiments.e3_speed_limit_vs_area(params=p)
    with st.next(f"E4 level-flight trim on the {backend} backend (dt = 1/12000 s, 20 s flights)"):
        e4 = experiments.e4_trim(p, backend=backend)
    with st.next(f"E5 time-step study on the {backend} backend"):
        e5 = experiments.e5_timestep(p, backend=backend)
    with st.next("figures 3-5"):
        figures.fig3_forces(e2, out / FIGURES["fig3"])
        figures.fig_speed_limit(sweep, out / FIGURES["speed_limit"])
        figures.fig4_trim(e4, out / FIGURES["fig4"])
        figures.fig5_timestep(e5, out / FIGURES["fig5"])
    results = {
        "paper": "Oe, Suzuki, Yamamoto, Furukawa 2010, a butterfly model for CG",
        "backend": backend,
        "params": asdict(p),
        "e1": e1.to_dict(),
        "e2": e2.to_dict(),
        "e3": e3.to_dict(),
        "e3_vs_area": sweep.to_dict(),
        "e4": e4.to_dict(),
        "e5": e5.to_dict(),
        "figures": dict(FIGURES),
        "elapsed_s": time.perf_counter() - t0,
    }
    write_text(out / "results.json", dumps(results, indent=1) + "\n")
    write_text(out / "report.md", _markdown(results, extra_sections))
    if stages is None:
        st.done(f"wrote {out / 'report.md'}")
    return results


def _compare_section(out: Path, params: ButterflyParams) -> tuple[str, list[dict]]:
    from lifelike_mj.butterfly.figures import fig_compare

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
            + "\n".join(rows) + "\n\n" + _figure("fig_compare_backends") + "\n")
    return body, [r.to_dict() for r in results]


def _snapshot_section(out: Path, params: ButterflyParams) -> str:
    try:
        from lifelike_mj.butterfly.render import snapshot_figure

        snapshot_figure(out / "fig10_snapshots.png", controllers.load("simple_rule"), params)
    except (UserError, ImportError, RuntimeError) as exc:
        return f"Snapshots not rendered on this machine: {exc}\n"
    return ("The MuJoCo model in settled flight, one frame every 0.025 s (the paper's Fig. 10 shows the "
            "evolved controller; here the simple rule).\n\n" + _figure("fig10_snapshots") + "\n")


def _yesno(flag: bool) -> str:
    return "yes" if flag else "no"


#: Captions of the figures of E6-E11 and of the extra sections (Oe 2010 figure numbers).
CAPTIONS = {
    "fig7_fitness": "Oe 2010 Fig. 7 — best and mean fitness H (eq. 13) per generation of the RCGA run that made ann_paper.",
    "fig8_flight": "Oe 2010 Fig. 8 — ann_paper from 0 m in still air: altitude against forward distance (E6).",
    "fig9_phi": "Oe 2010 Fig. 9 — the pitch φ the network chooses and the flap angle θ over the first seconds (E6).",
    "fig11_from_above": "Oe 2010 Fig. 11 — ann_paper from +10 m and other heights above the target (E7).",
    "fig12_sink": "Oe 2010 Fig. 12 — sink speed gliding (φ = 0, θ = 75°) against flapping with the network (E8).",
    "fig13_from_below": "Oe 2010 Fig. 13 — ann_paper from below the target: it does not climb back (E9).",
    "fig14_15_winds": "Oe 2010 Fig. 14 and 15 — flights in 2 m/s winds from four directions, air-relative (a) "
                      "and ground-velocity (b) inputs (E10).",
    "fig15_windmap": "Oe 2010 section 7.2 — pass/fail over uniform winds (a, b), the colour giving why a cell "
                     "fails (E11).",
    "fig_windmap_paper_vs_robust": "Beyond the paper — the wind maps of ann_paper and ann_robust side by side.",
    "fig_robust_from_below": "Beyond the paper — ann_paper and ann_robust from -10 m.",
    "fig_compare_backends": "The simple rule on the paper backend and on MuJoCo (paper and rich configurations).",
    "fig10_snapshots": "cf. Oe 2010 Fig. 10 — the MuJoCo model in flight, one frame every 0.025 s.",
}


def _figure(name: str) -> str:
    """A figure with its caption (Markdown)."""
    return markdown_figure(f"{name}.png", CAPTIONS[name])


def _state(v: dict) -> str:
    """How a flight ends: level within a band, or still falling or climbing (settled climb rate above
    5 cm/s over the last 10 s), with its final altitude."""
    rate = v.get("settled_climb_rate_cm_s")
    if rate is not None and abs(rate) > 5.0:
        return (f"{'falls' if rate < 0 else 'climbs'} at {abs(rate):.0f} cm/s over the last 10 s, "
                f"y(20 s) = {v['final_altitude_m']:+.1f} m")
    return f"level in {_band(v)}"


def _band(v: dict, digits: int = 2) -> str:
    """Settled altitude band ``[min, max] m`` of a flight's numbers."""
    return f"[{v['settled_altitude_min_m']:+.{digits}f}, {v['settled_altitude_max_m']:+.{digits}f}] m"


def _ann_section(out: Path, params: ButterflyParams) -> tuple[str, dict]:
    """E6-E11 with the shipped ``ann_paper`` (and ``ann_robust`` beside it): figures and a table."""
    from lifelike_mj.butterfly import ann_experiments as ax
    from lifelike_mj.butterfly import ann_figures as af

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
                         f"{_state(v)}; forward speed {v['settled_forward_speed_cm_s']:.0f} cm/s"))
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
    for n in ("fig7_fitness", "fig8_flight", "fig9_phi", "fig11_from_above", "fig12_sink", "fig13_from_below",
              "fig14_15_winds", "fig15_windmap"):
        if (out / f"{n}.png").exists():
            body += ["", _figure(n)]
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
                 "", _figure("fig_windmap_paper_vs_robust"), "", _figure("fig_robust_from_below")]
        data["robust"] = {"from_-10m": rb["from -10 m"], "still_air": rb["still air"],
                          "tail_wind": tw, "e11": {k: m.to_dict() for k, m in rmaps.items()}}
    return "\n".join(body) + "\n", data


def reproduce(out: str | Path, params: ButterflyParams | None = None, progress: bool = True) -> dict:
    """``lifelike-mj reproduce butterfly``: E1-E11 and the two-backend comparison; writes ``report.md``,
    ``results.json`` and the figures into ``out`` and returns the results."""
    out = Path(out)
    p = params or ButterflyParams()
    out.mkdir(parents=True, exist_ok=True)
    st = Stages("reproduce butterfly", 7, progress)
    with st.next("comparison runs (paper backend vs MuJoCo)"):
        cmp_body, cmp_data = _compare_section(out, p)
    with st.next("snapshots (Fig. 10 style)"):
        snap_body = _snapshot_section(out, p)
    with st.next("E6-E11 with the evolved controllers (flights, wind maps)"):
        ann_body, ann_data = _ann_section(out, p)
    results = report_e1_e5(out, p, extra_sections=[("Comparison of the two backends", cmp_body),
                                                       ("Snapshots (Fig. 10 style)", snap_body),
                                                       ("The evolved network: E6-E11 (Oe 2010 sections 6-7)", ann_body)],
                           progress=progress, stages=st)
    results["compare"] = cmp_data
    results["ann"] = ann_data
    from lifelike_mj.provenance import provenance

    results["provenance"] = provenance(params=asdict(p))
    write_json(out / "results.json", results)
    st.done(f"wrote {out / 'report.md'}")
    return results
