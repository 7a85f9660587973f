"""``lifelike-mj reproduce fish``: Satoi 2015's observations F1-F4 with the calibrated presets.

Writes into the output folder: ``report.md``, ``results.json``, the tracks of a 30 s swim of ten
``B-D`` fish (``tracks.npz``, ``tracks.csv``), the Fig. 7/8-style tracks and acceleration
histogram, the four-pattern comparison (the objective stand-in for the questionnaire of
Fig. 11-12) and a rendered frame of the tank when offscreen rendering is available.
"""

from __future__ import annotations

import math
from pathlib import Path

from lifelike_mj.errors import UserError
from lifelike_mj.fish.experiments import PATTERNS, drag_check, pattern_table, swim_summary, write_tracks
from lifelike_mj.fish.metrics import histogram_summary, resample, side_view, speed_and_accel
from lifelike_mj.fish.params import load_preset
from lifelike_mj.fish.scene import BODY_LENGTH_M
from lifelike_mj.fish.sim import swim
from lifelike_mj.io import write_json, write_text
from lifelike_mj.progress import Stages
from lifelike_mj.render.plot import markdown_figure

#: Settings of the report (the paper: ten fish, 30 s tracks).
N_FISH = 10
SWIM_S = 30.0
PATTERN_SEEDS = (0, 1, 2, 3, 4)
PATTERN_S = 60.0


def _f(x: float, d: int = 2) -> str:
    return f"{x:.{d}f}"


def reproduce_fish(out: str | Path, seeds=PATTERN_SEEDS, pattern_s: float = PATTERN_S, swim_s: float = SWIM_S,
                   progress: bool = True) -> dict:
    """Run everything; returns the results dictionary (also written as ``results.json``)."""
    from lifelike_mj.fish.figures import accel_histogram_figure, group_figure, patterns_figure, tracks_figure
    from lifelike_mj.fish.render import frame_png

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    bd = load_preset("B-D")
    st = Stages("reproduce fish", 4, progress)
    with st.next(f"F1-F3: {N_FISH} B-D fish, {swim_s:g} s"):
        r = swim(bd, N_FISH, swim_s, 0, progress=progress)
        write_tracks(r, out)
        tracks_figure(r, out / "fig7_tracks.png")
        accel_histogram_figure(r, out / "fig8_accel_histogram.png")
        group_figure(r, out / "group.png")
        summ = swim_summary(r)
        _, p = resample(r.times_s, side_view(r.positions))
        _, acc = speed_and_accel(p, 24.0)
        hist = histogram_summary(acc / BODY_LENGTH_M)
    with st.next("drag cross-check against MuJoCo's fluid model"):
        drag = drag_check()
    with st.next(f"F4: four patterns x {len(seeds)} seeds x {pattern_s:g} s"):
        table = pattern_table(seeds, pattern_s, N_FISH, progress=progress)
        patterns_figure(table.rows, out / "fig11_patterns.png")
    with st.next("a rendered frame of the tank"):
        try:
            frame_png(out / "tank.png", bd, n_fish=N_FISH, seed=0, t_s=5.0, camera="oblique", width=1280, height=720)
            snap = markdown_figure("tank.png", f"All {N_FISH} B-D fish in the filmed 5 m tank at t = 5 s (seed 0), a "
                                                "rendered frame of the MuJoCo scene; each fish is 7 cm long.") + "\n"
        except (UserError, ImportError, RuntimeError) as exc:
            snap = f"(no rendered frame on this machine: {exc})\n"

    g = summ["group"]
    k = g["kick_interval_s"]
    lines = ["# Tropical fish (Satoi, Nakadai, Hoshino 2015): reproduction report", ""]
    lines += ["## F1-F3: ten `B-D` fish, 30 s (seed 0)", "",
              "| observation | paper | ours |", "|---|---|---|",
              f"| F1 motion changes (bursts) | every 0.3-1 s (real fish) | a burst every "
              f"{_f(summ['burst_interval_mean_s'])} s (median {_f(summ['burst_interval_median_s'])} s) |",
              f"| F3 acceleration histogram | peaks near 0, leans positive, gentle and strong changes | mode "
              f"{_f(hist['mode'])} BL/s^2, skewness {_f(hist['skewness'])}, {100 * hist['fraction_positive']:.0f} % "
              f"positive, 5th-95th percentile [{_f(hist['p5'], 1)}, {_f(hist['p95'], 1)}] BL/s^2 |",
              f"| speed | (damselfish, 7 cm) | mean {_f(summ['mean_speed_body_lengths_s'])} BL/s, max "
              f"{_f(summ['max_speed_body_lengths_s'])} BL/s (side view, 24 fps) |",
              f"| fish outside the tank | - | {summ['fish_outside_tank']} |", "",
              "Living together, from the same tracks (the paper's fish ignore each other; `fish/shoal.py`):", "",
              "| measure | ours |", "|---|---|",
              f"| nearest neighbour | median {_f(g['nn_distance_bl']['median'], 1)} body lengths; "
              f"{100 * g['near_fraction_2bl']:.0f} % of the time within 2 |",
              f"| polarisation / milling | {_f(g['polarisation'])} / {_f(g['milling'])} (independent headings: about "
              f"{_f(math.sqrt(math.pi / (4 * N_FISH)))}) |",
              f"| kicks (speed rises of 0.5 BL/s or more) | every {_f(k['mean'])} s, CV {_f(k['cv'])}, 5th percentile "
              f"{_f(k['p5'])} s |",
              f"| distance to the nearest side wall | median {_f(g['wall_distance_bl']['median'], 1)} body lengths |", "",
              markdown_figure("fig7_tracks.png", "cf. Satoi 2015 Fig. 7 — one fish's speed, the motion unit it is in, "
                              "and its track seen from the side (F1, F2)."), "",
              markdown_figure("fig8_accel_histogram.png", "cf. Satoi 2015 Fig. 8 — histogram of the acceleration along "
                              "the side-view tracks of ten fish, 24 fps (F3)."), "",
              markdown_figure("group.png", "The same ten fish together: nearest neighbour, order parameters, kick "
                              "intervals, speed, distance to the wall, and where the neighbours are in a fish's frame."),
              "", snap]
    lines += ["## F4: the four patterns on objective measures", "",
              f"{len(seeds)} seeds x {_f(pattern_s, 0)} s x {N_FISH} fish; medians over seeds.", "",
              "| pattern | burstiness B | acceleration kurtosis | turning entropy (bits) | burst interval (s) | "
              "mean speed (BL/s) | MU entropy rate (bits/step) |", "|---|---|---|---|---|---|---|"]
    for name in PATTERNS:
        lines.append(f"| {name} | {_f(table.median(name, 'burstiness'), 3)} | {_f(table.median(name, 'accel_kurtosis'))} | "
                     f"{_f(table.median(name, 'turn_entropy'), 3)} | {_f(table.median(name, 'burst_interval_mean_s'))} | "
                     f"{_f(table.median(name, 'mean_speed_body_lengths_s'))} | "
                     f"{_f(table.median(name, 'mu_entropy_rate'), 3)} |")
    lines += ["", "Orderings the paper's ratings imply, checked seed by seed:", "",
              "| ordering | holds for every seed | margins per seed |", "|---|---|---|"]
    for k, c in table.checks.items():
        lines.append(f"| {k} | {'yes' if c['holds'] else '**no**'} | {', '.join(_f(m, 3) for m in c['margins'])} |")
    lines += ["", markdown_figure("fig11_patterns.png", "cf. Satoi 2015 section 5.1 — the four patterns (bursty or "
                                  "not, diverse or not) on the objective measures, one point per seed (F4)."), "",
              "## Drag cross-check", "",
              f"Custom drag (C_D = 1, equivalent-inertia-box areas) against MuJoCo's inertia-box fluid model over "
              f"{drag['trials']} random states: max relative error {drag['max_rel_error']:.1e}.", ""]
    write_text(out / "report.md", "\n".join(lines))
    results = {"swim": summ, "accel_histogram": hist, "drag_check": drag, "patterns": table.to_dict()}
    from lifelike_mj.provenance import provenance

    results["provenance"] = provenance(seeds=list(seeds), pattern_s=pattern_s, swim_s=swim_s, n_fish=N_FISH)
    write_json(out / "results.json", results)
    st.done(f"wrote {out / 'report.md'}")
    return results


#: ``lifelike-mj reproduce fish`` from Python (the package's common name).
reproduce = reproduce_fish
