"""``lifelike-mj reproduce boids``: Nakamura 2013's findings with objective measures.

Writes into the output folder ``report.md``, ``results.json`` and the figures: Fig. 2 (the
homogeneous grid, with the divergence checks of section 2.2), Fig. 4-5 (the eight patterns), the
confusion table of the classifier over seeds, the robustness of the robust patterns to small changes
of their matrices, and a phase diagram over the cross-type weights (the map the paper sketched).
Runs go through the project's evaluator (``executor``: serial, process or ray).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from lifelike_mj.boids.engine import N_AGENTS
from lifelike_mj.boids.experiments import TWO_TYPE_LABELS as LABELS
from lifelike_mj.boids.experiments import Sweep, classified_run, run_settings, run_sweep
from lifelike_mj.boids.figures import PATTERN_NAMES
from lifelike_mj.boids.presets import PATTERNS, homogeneous, load_grid, load_preset
from lifelike_mj.errors import UserError
from lifelike_mj.io import write_json, write_text
from lifelike_mj.progress import Stages
from lifelike_mj.render.plot import markdown_figure

SEEDS = (0, 1, 2, 3, 4)
ROBUST = ("4a", "4b", "4c", "5a", "5c", "5d")
#: Small changes of a matrix: every nonzero entry of W_a (then of W_c) times these factors.
PERTURBATIONS = (0.8, 1.2)


def _perturbed(name: str, which: str, factor: float):
    p = load_preset(name)
    m = np.array(getattr(p, which)) * factor
    return replace(p, **{which: tuple(map(tuple, m.tolist()))}, name=f"{name} {which}x{factor:g}")


CAPTIONS = {
    "patterns": "cf. Nakamura 2013 Fig. 4 and 5 — the eight presets (seed 0), trails of the last 5 steps, each "
                "titled with the label the classifier gives it.",
    "fig2": "cf. Nakamura 2013 Fig. 2 — one type over the alignment weight w_a (rows) and the cohesion weight w_c "
            "(columns), seed 0.",
    "phase": "Beyond the paper — the classified pattern over the cross-type weights around 5a (seed 0).",
}


def _paper_fig2(w_a: float, w_c: float) -> str:
    """What Nakamura 2013 section 2.2 says of one type at ``(w_a, w_c)``."""
    a = "aligned, lattice-like" if w_a >= 1 else "midge-like swarm" if w_a >= 0.01 else "spread, no alignment"
    c = "fast compact flock" if w_c >= 0.1 else "no clear flock" if w_c == 0 else "spreads and slows"
    return f"{a}; {c}"


def _runs(params_list, seeds, executor, workers, bar=None):
    """Rows (label, paper_picture, measures) of each (params, seed), one Sweep per parameter set."""
    rows = []
    for p in params_list:
        rows.append(run_sweep(Sweep(p, ()), [], seeds, executor=executor, workers=workers)["rows"])
        if bar is not None:
            bar.update(1)
    return rows


def reproduce_boids(out: str | Path, seeds=SEEDS, executor: str = "process", workers: int | None = None,
                    phase_steps: int = 7, progress: bool = True) -> dict:
    from lifelike_mj.boids.figures import homogeneous_grid_figure, patterns_grid_figure, phase_diagram_figure

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    settings = run_settings()
    results: dict = {"settings": settings, "seeds": list(seeds)}
    st = Stages("reproduce boids", 6, progress)

    # Fig. 4-5: one classified run per pattern (seed 0), drawn in the paper's style
    runs = {}
    with st.next("Fig. 4-5: the eight patterns, seed 0", total=len(PATTERNS), unit="run") as b:
        for name in PATTERNS:
            run, m, label, _ = classified_run(load_preset(name), N_AGENTS, 0)
            runs[f"{name} (classified {label})"] = run
            b.update(1)
        patterns_grid_figure(runs, out / "fig4_5_patterns.png")

    # confusion table over seeds
    with st.next(f"confusion table: eight patterns x {len(seeds)} seeds", total=len(PATTERNS), unit="pattern") as b:
        rows = _runs([load_preset(n) for n in PATTERNS], seeds, executor, workers, b)
    confusion, pictures = {}, {}
    for name, rr in zip(PATTERNS, rows):
        labs = [r["label"] for r in rr]
        confusion[name] = {lab: labs.count(lab) for lab in LABELS if labs.count(lab)}
        pictures[name] = sum(1 for r in rr if r["label"] == name and r["paper_picture"])
    results["confusion"] = confusion
    results["confusion_rows"] = dict(zip(PATTERNS, rows))

    # robustness of the robust patterns
    pert = [(name, which, f) for name in ROBUST for which in ("wa", "wc") for f in PERTURBATIONS]
    with st.next(f"robust patterns under perturbed matrices x {len(seeds[:2])} seeds", total=len(pert),
                 unit="matrix") as b:
        prows = _runs([_perturbed(*x) for x in pert], seeds[:2], executor, workers, b)
    results["perturbations"] = [{"preset": n, "matrix": w, "factor": f, "labels": [r["label"] for r in rr]}
                                for (n, w, f), rr in zip(pert, prows)]

    # Fig. 2: the homogeneous grid, and divergence
    g = load_grid()
    grid_runs = {}
    with st.next("Fig. 2: the homogeneous grid", total=len(g["w_a"]) * len(g["w_c"]), unit="run") as b:
        for wa in g["w_a"]:
            for wc in g["w_c"]:
                try:
                    run, m, _, _ = classified_run(homogeneous(wa, wc), N_AGENTS, 0)
                    grid_runs[(wa, wc)] = run
                except UserError:
                    grid_runs[(wa, wc)] = None
                b.update(1)
        homogeneous_grid_figure(grid_runs, out / "fig2_homogeneous.png")
    from lifelike_mj.boids import metrics

    hom = []
    for (wa, wc), run in grid_runs.items():
        if run is None:
            hom.append({"w_a": wa, "w_c": wc, "diverged": True})
            continue
        m = metrics.measures(run, window=settings["window"])
        hom.append({"w_a": wa, "w_c": wc, "diverged": False, "regime": metrics.classify_homogeneous(m)[0],
                    **{k: m.get(k) for k in (
            "polarisation", "speed", "n_groups", "nn_distance", "radius_of_gyration") if k in m}})
    results["homogeneous"] = hom
    div = []
    with st.next("divergence (section 2.2)", total=4, unit="run") as b:
        for wa, wc in ((10.0, 0.01), (0.1, 1.0), (1.0, 1.0), (0.001, 1.0)):
            try:
                classified_run(homogeneous(wa, wc), N_AGENTS, 0)
                div.append({"w_a": wa, "w_c": wc, "diverged": False})
            except UserError as exc:
                div.append({"w_a": wa, "w_c": wc, "diverged": True, "message": str(exc)})
            b.update(1)
    results["divergence"] = div

    # phase diagram over the cross-type weights, diagonal of 5a (W_a = 0.5, W_c = 0.01)
    xa = [float(x) for x in np.linspace(-0.3, 0.5, phase_steps)]
    yc = [float(x) for x in np.linspace(-0.01, 0.01, phase_steps)]
    with st.next(f"phase diagram over the cross-type weights ({phase_steps} x {phase_steps} runs)",
                 total=len(xa) * len(yc), unit="run") as b:
        ph = run_sweep(Sweep(load_preset("5a"), ("wa_cross", "wc_cross")), [xa, yc], [0], executor=executor,
                       workers=workers, bar=b)
    lab = np.array([[ph["majority"][f"{a:g},{b:g}"] for a in xa] for b in yc])
    phase_diagram_figure(lab, xa, yc, "cross-type alignment w_aAB = w_aBA", "cross-type cohesion w_cAB = w_cBA",
                         out / "phase_diagram.png",
                         title=f"Classified patterns around 5a (W_a diagonal 0.5, W_c diagonal 0.01): n = {N_AGENTS}, "
                               f"{settings['n_steps']} steps, seed 0")
    results["phase_diagram"] = ph

    # report
    L = ["# Heterogeneous boids (Nakamura 2013): reproduction report", "",
         f"n = {N_AGENTS}, box 20, R_s = 1, R_a = 2.5, R_c = 4.5, w_s = 0.05, dt = 1; runs of "
         f"{settings['n_steps']} steps, measures averaged over the last {settings['window']} steps.", "",
         "## Fig. 4-5: the eight patterns (seed 0)", "", markdown_figure("fig4_5_patterns.png", CAPTIONS["patterns"]),
         "", f"## Paper vs ours: the classified label of each preset (seeds {', '.join(map(str, seeds))})", "",
         "| preset | paper (its picture) | ours: own label | ours: own label and the paper's picture | "
         + " | ".join(LABELS) + " |",
         "|---" * (len(LABELS) + 4) + "|"]
    for name in PATTERNS:
        c = confusion[name]
        L.append(f"| {name} | {PATTERN_NAMES[name]} | {c.get(name, 0)}/{len(seeds)} | {pictures[name]}/{len(seeds)} | "
                 + " | ".join(str(c.get(lab, 0)) for lab in LABELS) + " |")
    L += ["", "## Robust patterns under small changes of their matrices (seeds 0, 1)", "",
          "| preset | matrix | factor | labels |", "|---|---|---|---|"]
    for r in results["perturbations"]:
        L.append(f"| {r['preset']} | {r['matrix']} | {r['factor']:g} | {', '.join(r['labels'])} |")
    L += ["", "## Fig. 2: homogeneous boids", "", markdown_figure("fig2_homogeneous.png", CAPTIONS["fig2"]), "",
          "| w_a | w_c | paper (section 2.2) | ours: regime | polarisation | mean speed | groups | "
          "nearest-neighbour distance |", "|---|---|---|---|---|---|---|---|"]

    def f3(x):
        return "" if x is None else f"{x:.3g}"

    for h in hom:
        ours = "diverged" if h["diverged"] else h.get("regime", "")
        L.append(f"| {h['w_a']:g} | {h['w_c']:g} | {_paper_fig2(h['w_a'], h['w_c'])} | {ours} | "
                 f"{f3(h.get('polarisation'))} | {f3(h.get('speed'))} | {h.get('n_groups', '')} | "
                 f"{f3(h.get('nn_distance'))} |")
    L += ["", "Divergence (section 2.2):", ""]
    for d in div:
        L.append(f"* w_a = {d['w_a']:g}, w_c = {d['w_c']:g}: {'diverged: ' + d['message'] if d['diverged'] else 'no'}")
    L += ["", "## Phase diagram over the cross-type weights (diagonal of 5a)", "",
          markdown_figure("phase_diagram.png", CAPTIONS["phase"]), ""]
    write_text(out / "report.md", "\n".join(L))
    from lifelike_mj.provenance import provenance

    results["provenance"] = provenance(seeds=list(seeds), executor=executor, workers=workers, phase_steps=phase_steps)
    write_json(out / "results.json", results)
    st.done(f"wrote {out / 'report.md'}")
    return results


#: ``lifelike-mj reproduce boids`` from Python (the package's common name).
reproduce = reproduce_boids
