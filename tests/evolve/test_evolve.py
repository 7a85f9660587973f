"""Tests of lifelike_mj.evolve: the five optimisers, evaluators, checkpoints, resume and interruption."""

from __future__ import annotations

import json
import os
import pickle
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from lifelike_mj.errors import UserError
from lifelike_mj.evolve import (
    OPTIMIZERS,
    Rastrigin,
    Sphere,
    make_evaluator,
    minimum_population,
    optimize,
)
from lifelike_mj.evolve import rcga as ga
from lifelike_mj.evolve.checkpoint import FORMAT, VERSION, load_checkpoint, save_checkpoint

ROOT = Path(__file__).resolve().parents[1]
WORKER = Path(__file__).parent.parent / "evolve_worker.py"

#: Small settings per optimiser (Sphere/Rastrigin in 3-4 dimensions): population, generations.
SMALL = {"rcga": (12, 12), "cmaes": (8, 12), "crs2": (10, 12), "esch": (10, 12), "isres": (12, 12)}


def _run(problem, name, seed=1, **kw):
    population, generations = SMALL[name]
    kw.setdefault("population", population)
    if "evaluations" not in kw:
        kw.setdefault("generations", generations)
    return optimize(problem, name, seed=seed, progress=False, **kw)


def _same(a, b) -> None:
    """Bit-identical outcome (times aside)."""
    assert a.best_f == b.best_f
    assert a.best_x.tobytes() == b.best_x.tobytes()
    assert a.evaluations == b.evaluations
    assert a.generations == b.generations
    assert [h["best"] for h in a.history] == [h["best"] for h in b.history]
    assert [h["mean"] for h in a.history] == [h["mean"] for h in b.history]
    assert [h["evaluations"] for h in a.history] == [h["evaluations"] for h in b.history]


class Recording(Sphere):
    """A Sphere that remembers every row it evaluated (serial evaluation only)."""

    def __init__(self, *args, **kw):
        super().__init__(*args, **kw)
        self.seen: list[np.ndarray] = []

    def evaluate(self, X):
        self.seen.extend(np.array(X, copy=True))
        return super().evaluate(X)


# --- every optimiser --------------------------------------------------------------------------------

@pytest.mark.parametrize("name", OPTIMIZERS)
def test_improves_on_first_generation(name):
    p = Sphere(dim=4, shift=1.0)  # the middle of the bounds is far from the optimum
    res = _run(p, name)
    bests = [h["best"] for h in res.history]
    assert bests[-1] < bests[0]
    assert all(b2 <= b1 for b1, b2 in zip(bests, bests[1:]))  # best so far never worsens
    assert res.best_f == bests[-1] == float(p.evaluate(res.best_x[None])[0])
    assert res.generations == len(res.history) == SMALL[name][1]
    assert res.history[-1]["evaluations"] == res.evaluations
    assert not res.interrupted and not res.resumed
    assert [h["generation"] for h in res.history] == list(range(1, res.generations + 1))
    json.dumps(res.to_dict())


@pytest.mark.parametrize("name", OPTIMIZERS)
def test_same_seed_identical_different_seed_differs(name):
    p = Rastrigin(dim=3)
    _same(_run(p, name, seed=7), _run(p, name, seed=7))
    assert _run(p, name, seed=8).best_x.tobytes() != _run(p, name, seed=7).best_x.tobytes()


@pytest.mark.parametrize("name", OPTIMIZERS)
def test_maximize_mirrors_minimize(name):
    lo = _run(Rastrigin(dim=3), name, seed=4)
    hi = _run(Rastrigin(dim=3, maximize=True), name, seed=4)
    assert hi.best_f == -lo.best_f
    assert hi.best_x.tobytes() == lo.best_x.tobytes()
    assert [h["best"] for h in hi.history] == [-h["best"] for h in lo.history]
    assert hi.history[-1]["best"] > hi.history[0]["best"]


@pytest.mark.parametrize("name", ["cmaes", "crs2", "esch", "isres"])
def test_bounded_optimizers_stay_in_bounds(name):
    p = Recording(dim=3, shift=1.9, low=-1.0, high=2.0)
    _run(p, name)
    seen = np.array(p.seen)
    assert np.all(seen >= -1.0) and np.all(seen <= 2.0)


@pytest.mark.parametrize("name", ["crs2", "esch", "isres"])
def test_nlopt_budget_exact(name):
    res = _run(Sphere(dim=3), name, evaluations=95)
    assert res.evaluations == 95
    assert res.generations == -(-95 // SMALL[name][0])  # last block shorter


def test_default_populations_and_budget():
    res = optimize(Sphere(dim=3), "rcga", seed=0, generations=2, progress=False)
    assert res.population == 40 and res.evaluations == 40 + 39
    assert optimize(Sphere(dim=3), "cmaes", seed=0, generations=1, progress=False).population == 4 + int(3 * np.log(3))
    assert optimize(Sphere(dim=3), "crs2", seed=0, generations=1, progress=False).population == 40
    assert minimum_population("crs2", 5) == 6 and minimum_population("rcga", 5) == 3
    assert minimum_population("cmaes", 5) == 4 and minimum_population("isres", 5) == 1


# --- rcga specifics ---------------------------------------------------------------------------------

def test_rcga_counts_and_elite():
    N, G = 9, 15
    elites = []
    seen_gen = []

    def look(rec):
        seen_gen.append(rec["generation"])

    res = optimize(Sphere(dim=3), "rcga", seed=2, population=N, generations=G, progress=False, on_generation=look)
    assert res.evaluations == N + (G - 1) * (N - 1)  # the unchanged elite is not re-evaluated
    assert seen_gen == list(range(1, G + 1))
    rng = np.random.default_rng(0)
    P = rng.uniform(-1, 1, (N, 3))
    f = Sphere(dim=3).evaluate(P)
    for _ in range(20):
        e = ga.elite_index(f, False)
        nxt = ga.next_generation(P, f, rng, False)
        assert np.array_equal(nxt[0], P[e])  # index 0: the elite, unchanged
        g = Sphere(dim=3).evaluate(nxt)
        assert g[0] == f[e]
        elites.append(g.min())
        P, f = nxt, g
    assert all(b <= a for a, b in zip(elites, elites[1:]))  # elite never gets worse


def test_rcga_selection_composition():
    rng = np.random.default_rng(1)
    N, dim = 30, 4
    P = rng.normal(0, 3, (N, dim))  # outside [-1, 1], so fresh individuals are recognisable
    f = Sphere(dim=dim, shift=0.0).evaluate(P)
    ranks = np.argsort(np.argsort(f))  # 0 = best
    winner_ranks = []
    for _ in range(200):
        Q = ga.select(P, f, rng, maximize=False)
        for j in range(N):
            if j % 3 == 0:
                assert np.array_equal(Q[j], P[np.argmin(f)])
            elif j % 3 == 1:
                match = np.flatnonzero((P == Q[j]).all(axis=1))
                assert match.size == 1
                winner_ranks.append(ranks[match[0]])
            else:
                assert np.all(np.abs(Q[j]) <= 1.0)
                assert not (P == Q[j]).all(axis=1).any()
    # a size-2 tournament picks rank r with probability ((N-r)^2 - (N-r-1)^2) / N^2
    r = np.arange(N)
    expected = np.sum(r * ((N - r) ** 2 - (N - r - 1) ** 2)) / N**2
    assert abs(np.mean(winner_ranks) - expected) < 0.6
    assert np.mean(winner_ranks) < (N - 1) / 2  # better than random choice


def test_rcga_blx_range_and_pairing():
    rng = np.random.default_rng(2)
    alpha = ga.ALPHA
    outside = inside = 0
    for N in (3, 4, 10, 11):
        for _ in range(50):
            Q = rng.uniform(-1, 1, (N, 5))
            C, pairs = ga.crossover(Q, rng)
            assert np.array_equal(C[0], Q[0])  # index 0 untouched
            full = (N - 1) // 2  # pairs that produce two children; an odd one out produces one
            assert len(pairs) == full + (N - 1) % 2
            replaced = [c for k, (i, j) in enumerate(pairs) for c in ((i, j) if k < full else (i,))]
            assert sorted(replaced) == list(range(1, N))  # everyone but 0 replaced exactly once
            for k, (i, j) in enumerate(pairs):
                assert i != j
                lo, hi = np.minimum(Q[i], Q[j]), np.maximum(Q[i], Q[j])
                d = hi - lo
                children = [i, j] if k < full else [i]
                for c in children:
                    assert np.all(C[c] >= lo - alpha * d) and np.all(C[c] <= hi + alpha * d)
                    outside += int(np.sum((C[c] < lo) | (C[c] > hi)))
                    inside += int(np.sum((C[c] >= lo) & (C[c] <= hi)))
    # uniform on [lo - a d, hi + a d]: a fraction 2a / (1 + 2a) lies outside [lo, hi]
    assert abs(outside / (outside + inside) - 2 * alpha / (1 + 2 * alpha)) < 0.03


def test_rcga_mutation_rate():
    rng = np.random.default_rng(3)
    C = rng.uniform(0.5, 1.0, (2001, 50))
    M, mask = ga.mutate(C, rng)
    assert not mask[0].any() and np.array_equal(M[0], C[0])
    rate = mask[1:].mean()
    sigma = np.sqrt(0.01 * 0.99 / mask[1:].size)
    assert abs(rate - 0.01) < 5 * sigma
    assert np.array_equal(M[~mask], C[~mask])
    ratio = M[mask] / C[mask]
    assert np.all(np.abs(ratio) <= 2.0) and ratio.min() < -1.0 and ratio.max() > 1.0


def test_rcga_initial_genes_and_no_clipping():
    p = Recording(dim=3, shift=5.0, low=-1.0, high=1.0)  # optimum far outside [-1, 1]
    optimize(p, "rcga", seed=0, population=12, generations=30, progress=False)
    seen = np.array(p.seen)
    assert np.all(np.abs(seen[:12]) <= 1.0)
    assert seen.max() > 1.0  # the GA leaves the initial box: no clipping


# --- interruption and resume ------------------------------------------------------------------------

def _stop_at(k):
    def on_generation(rec):
        if rec["generation"] == k:
            raise KeyboardInterrupt
    return on_generation


@pytest.mark.parametrize("name", OPTIMIZERS)
@pytest.mark.parametrize("budget", [{"generations": 10}, {"evaluations": 110}])
def test_interrupt_then_resume_equals_uninterrupted(tmp_path, name, budget):
    p = Rastrigin(dim=3)
    full = _run(p, name, seed=3, **budget)
    ckpt = tmp_path / "run.ckpt"
    part = _run(p, name, seed=3, checkpoint=ckpt, on_generation=_stop_at(4), **budget)
    assert part.interrupted and part.generations == 4
    assert part.best_f == full.history[3]["best"]
    data = load_checkpoint(ckpt)
    assert data["format"] == FORMAT and data["version"] == VERSION and not data["finished"]
    assert data["generations"] == 4 and data["optimizer"] == name
    rest = _run(p, name, seed=3, checkpoint=ckpt, resume=True, **budget)
    assert rest.resumed and not rest.interrupted
    _same(rest, full)
    assert load_checkpoint(ckpt)["finished"]
    # a finished checkpoint returns its result without evaluating anything
    with make_evaluator(p, "serial") as ev:
        again = _run(p, name, seed=3, checkpoint=ckpt, resume=True, evaluator=ev, **budget)
        assert ev.evaluations == 0
    _same(again, full)


def test_cmaes_resume_across_ipop_restart(tmp_path):
    p = Sphere(dim=2)
    ckpt = tmp_path / "c.ckpt"
    sizes = []
    full = optimize(p, "cmaes", seed=5, population=4, generations=140, progress=False, checkpoint=ckpt,
                    on_generation=lambda rec: sizes.append(int(load_checkpoint(ckpt)["state"]["sizes"][-1])))
    assert max(sizes) >= 8  # converged and restarted with a doubled population
    first = sizes.index(8) + 1
    for k in (first - 1, first + 3):
        optimize(p, "cmaes", seed=5, population=4, generations=140, progress=False, checkpoint=ckpt,
                 on_generation=_stop_at(k), overwrite=True)
        rest = optimize(p, "cmaes", seed=5, population=4, generations=140, progress=False, checkpoint=ckpt, resume=True)
        _same(rest, full)


def test_cmaes_leaves_global_rng_alone():
    np.random.seed(123)
    expected = np.random.get_state()[1].copy()
    _run(Sphere(dim=3), "cmaes")
    assert np.array_equal(np.random.get_state()[1], expected)


def test_resume_without_file_starts_fresh(tmp_path):
    p = Sphere(dim=3)
    res = _run(p, "rcga", checkpoint=tmp_path / "new.ckpt", resume=True)
    assert not res.resumed
    _same(res, _run(p, "rcga"))
    assert (tmp_path / "new.ckpt").exists()


def test_nlopt_replay_divergence_is_reported(tmp_path):
    p = Sphere(dim=3)
    ckpt = tmp_path / "n.ckpt"
    _run(p, "crs2", checkpoint=ckpt, on_generation=_stop_at(3))
    data = load_checkpoint(ckpt)
    data["state"]["X"][5, 0] += 1e-12
    save_checkpoint(ckpt, {k: v for k, v in data.items() if k not in ("format", "version", "saved_at", "package")})
    with pytest.raises(UserError, match="diverged"):
        _run(p, "crs2", checkpoint=ckpt, resume=True)


# --- real signals in a subprocess -------------------------------------------------------------------

def _start_worker(ckpt, name, population, generations, delay_s, executor="serial", workers=1, new_session=False):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    args = [sys.executable, str(WORKER), str(ckpt), name, "3", str(population), str(generations), str(delay_s), executor,
            str(workers)]
    return subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            start_new_session=new_session)


def _wait_for_generation(proc, ckpt, k, timeout=30.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            pytest.fail(f"worker exited early: {proc.communicate()}")
        if ckpt.exists():
            try:
                if load_checkpoint(ckpt)["generations"] >= k:
                    return
            except Exception:
                pass
        time.sleep(0.02)
    proc.kill()
    pytest.fail("worker made no progress")


@pytest.mark.parametrize("name,sig,executor", [
    ("rcga", signal.SIGINT, "serial"),
    ("cmaes", signal.SIGINT, "process"),  # Ctrl-C to the whole process group: workers ignore it
    ("esch", signal.SIGTERM, "serial"),
    ("crs2", signal.SIGKILL, "serial"),
    ("rcga", signal.SIGKILL, "serial"),
])
def test_real_signal_then_resume(tmp_path, name, sig, executor):
    population, generations = 8, 200  # far more than the few generations before the signal
    p = Rastrigin(dim=3)
    ckpt = tmp_path / "sig.ckpt"
    delay = 0.02 if name in ("rcga", "cmaes") else 0.003
    proc = _start_worker(ckpt, name, population, generations, delay, executor, workers=2,
                         new_session=executor == "process")
    try:
        _wait_for_generation(proc, ckpt, 3)
        if executor == "process":
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    if sig == signal.SIGKILL:
        assert proc.returncode == -signal.SIGKILL
    else:
        assert proc.returncode == 0, err
        result = json.loads(out.strip().splitlines()[-1])
        assert result["interrupted"] and result["generations"] < generations
    done = load_checkpoint(ckpt)["generations"]
    assert 3 <= done < generations
    rest = optimize(p, name, seed=3, population=population, generations=generations, checkpoint=ckpt, resume=True,
                    progress=False)
    assert rest.resumed
    _same(rest, optimize(p, name, seed=3, population=population, generations=generations, progress=False))


# --- evaluators -------------------------------------------------------------------------------------

def test_process_evaluator_matches_serial():
    p = Rastrigin(dim=3)
    X = np.random.default_rng(0).uniform(-2, 2, (7, 3))
    with make_evaluator(p, "serial") as s, make_evaluator(p, "process", workers=2) as q:
        assert q(X).tobytes() == s(X).tobytes() == p.evaluate(X).tobytes()
        assert q(X[:1]).tobytes() == s(X[:1]).tobytes()
        assert q.calls == 2 and q.evaluations == 8
        for name in ("rcga", "cmaes", "isres"):
            _same(_run(p, name, evaluator=q), _run(p, name, evaluator=s))


def test_ray_evaluator_matches_serial(local_ray):
    p = Rastrigin(dim=3)
    with make_evaluator(p, "ray", workers=2) as r:
        X = np.random.default_rng(1).uniform(-2, 2, (5, 3))
        assert r(X).tobytes() == p.evaluate(X).tobytes()
        for name in ("rcga", "cmaes"):
            _same(_run(p, name, evaluator=r), _run(p, name))
    assert local_ray.is_initialized()  # the evaluator leaves a cluster it did not start


def test_ray_missing_is_a_user_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(UserError, match="ray"):
        make_evaluator(Sphere(dim=2), "ray")


# --- bad inputs -------------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs,match", [
    ({"optimizer": "ga"}, "unknown optimizer 'ga'; known optimizers are rcga, cmaes, crs2, esch, isres"),
    ({"optimizer": "rcga", "population": 2}, "population 2 is below the minimum 3 for rcga"),
    ({"optimizer": "cmaes", "population": 3}, "population 3 is below the minimum 4 for cmaes"),
    ({"optimizer": "crs2", "population": 3}, "population 3 is below the minimum 4 for crs2"),
    ({"optimizer": "rcga", "generations": 0}, "generations must be a positive integer"),
    ({"optimizer": "rcga", "generations": None, "evaluations": -5}, "evaluations must be a positive integer"),
    ({"optimizer": "rcga", "generations": 5, "evaluations": 50}, "not both"),
    ({"optimizer": "rcga", "seed": -1}, "seed must be a non-negative integer"),
    ({"optimizer": "rcga", "resume": True}, "needs a checkpoint"),
])
def test_bad_arguments(kwargs, match):
    args = {"seed": 0, "generations": 2, "progress": False, **kwargs}
    with pytest.raises(UserError, match=match):
        optimize(Sphere(dim=3), args.pop("optimizer"), **args)


def test_bad_problems_and_executors():
    class Unbounded(Sphere):
        pass

    p = Unbounded(dim=2)
    p.upper = np.array([1.0, np.inf])
    with pytest.raises(UserError, match="finite"):
        optimize(p, "cmaes", seed=0, generations=1, progress=False)
    optimize(p, "rcga", seed=0, generations=1, progress=False)  # rcga ignores bounds
    with pytest.raises(UserError, match="lacks"):
        optimize(object(), "rcga", seed=0, generations=1, progress=False)
    with pytest.raises(UserError, match="unknown executor 'threads'"):
        make_evaluator(Sphere(dim=2), "threads")
    with pytest.raises(UserError, match="workers"):
        make_evaluator(Sphere(dim=2), "process", workers=0)
    with make_evaluator(Sphere(dim=2), "serial") as ev, pytest.raises(UserError, match="different problem"):
        optimize(Sphere(dim=3), "rcga", seed=0, generations=1, progress=False, evaluator=ev)


def test_checkpoint_mismatches(tmp_path):
    ckpt = tmp_path / "run.ckpt"
    _run(Sphere(dim=3), "rcga", checkpoint=ckpt, on_generation=_stop_at(2))
    with pytest.raises(UserError, match=r"run\.ckpt is from a different problem"):
        _run(Sphere(dim=3, shift=0.1), "rcga", checkpoint=ckpt, resume=True)
    with pytest.raises(UserError, match="optimizer 'rcga'"):
        _run(Sphere(dim=3), "esch", checkpoint=ckpt, resume=True)
    with pytest.raises(UserError, match="seed 1"):
        _run(Sphere(dim=3), "rcga", seed=2, checkpoint=ckpt, resume=True)
    with pytest.raises(UserError, match="population 12"):
        _run(Sphere(dim=3), "rcga", population=13, checkpoint=ckpt, resume=True)
    with pytest.raises(UserError, match="budget generations=12"):
        _run(Sphere(dim=3), "rcga", generations=20, checkpoint=ckpt, resume=True)
    ckpt.write_bytes(b"not a checkpoint")
    with pytest.raises(UserError, match="not a lifelike_mj.evolve checkpoint"):
        _run(Sphere(dim=3), "rcga", checkpoint=ckpt, resume=True)
    np.savez(ckpt.with_suffix(".npz"), meta=np.frombuffer(b'{"format": "something else"}', dtype=np.uint8))
    ckpt.with_suffix(".npz").replace(ckpt)
    with pytest.raises(UserError, match="not a lifelike_mj.evolve checkpoint"):
        _run(Sphere(dim=3), "rcga", checkpoint=ckpt, resume=True)


class _Marker:
    """Unpickling this would write a marker file (what a crafted checkpoint would do)."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return (open, (self.path, "w"))


def test_a_crafted_checkpoint_runs_no_code(tmp_path):
    ckpt, marker = tmp_path / "evil.ckpt", tmp_path / "marker"
    # an old-style pickled checkpoint whose loading would create the marker
    ckpt.write_bytes(pickle.dumps({"format": FORMAT, "version": 1, "x": _Marker(marker)}))
    with pytest.raises(UserError, match="pickle can run code"):
        _run(Sphere(dim=3), "rcga", checkpoint=ckpt, resume=True)
    # a zip checkpoint smuggling a pickled object array into one of its members
    with open(ckpt, "wb") as fh:
        np.savez(fh, meta=np.frombuffer(b'{"format": "%s", "version": %d, "state": {"__array__": "a0"}}'
                                        % (FORMAT.encode(), VERSION), dtype=np.uint8),
                 a0=np.array([_Marker(marker)], dtype=object))
    with pytest.raises(UserError, match="unreadable|lacks"):
        _run(Sphere(dim=3), "rcga", checkpoint=ckpt, resume=True)
    assert not marker.exists()


def test_checkpoint_is_strict_data(tmp_path):
    """The checkpoint is a zip of .npy members; its meta is strict JSON (no NaN), readable without this package."""
    import json
    import zipfile

    ckpt = tmp_path / "run.ckpt"
    _run(Sphere(dim=3), "cmaes", checkpoint=ckpt, on_generation=_stop_at(3))
    with zipfile.ZipFile(ckpt) as z:
        assert all(n.endswith(".npy") for n in z.namelist())
    with np.load(ckpt, allow_pickle=False) as z:
        meta = json.loads(z["meta"].tobytes().decode(), parse_constant=lambda c: pytest.fail(f"bare {c} in meta"))
        assert meta["format"] == FORMAT and meta["version"] == VERSION and meta["generations"] == 3


def test_progress_bar_goes_to_stderr(capsys):
    optimize(Sphere(dim=2), "rcga", seed=0, population=6, generations=3)
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "3/3" in captured.err and "best=" in captured.err


def test_a_problem_the_pool_cannot_take_runs_serially_with_a_warning():
    from lifelike_mj.evolve import Sphere, make_evaluator
    from lifelike_mj.evolve.evaluators import SerialEvaluator, pool_problem_error

    class Local(Sphere):  # defined in a function: not picklable
        pass

    problem = Local(dim=2)
    assert "pickled" in pool_problem_error(problem)
    assert pool_problem_error(Sphere(dim=2)) is None
    with pytest.warns(RuntimeWarning, match="serially"):
        ev = make_evaluator(problem, "process", workers=2)
    with ev:
        assert isinstance(ev, SerialEvaluator)
        assert ev(np.zeros((3, 2))).shape == (3,)


# --- the driver's and CMA-ES's documented choices, each checked by its effect --------------------------


def test_cmaes_starts_with_a_quarter_of_the_bounds_width():
    """sigma0 = 0.25 mean(upper - lower): the first generation's spread about the centre of wide bounds."""
    asked = []

    def record(X):
        asked.append(np.array(X))
        return np.sum(X * X, axis=1)

    p = Sphere(dim=50, low=-100.0, high=100.0)
    optimize(p, "cmaes", seed=3, generations=1, evaluator=record, progress=False)
    X = asked[0]
    # the median |x| of N(0, sigma) is 0.6745 sigma, measured where pycma's bound handling is the identity
    assert np.median(np.abs(X)) / 0.6745 == pytest.approx(0.25 * 200.0, rel=0.1)


@pytest.mark.parametrize("maximize", [False, True])
def test_nan_fitness_counts_as_the_worst(maximize):
    p = Sphere(dim=3, maximize=maximize)

    def with_nan(X):
        f = np.sum(X * X, axis=1)
        f[0] = np.nan
        return f

    res = optimize(p, "rcga", seed=0, population=9, generations=3, evaluator=with_nan, progress=False)
    assert np.isfinite(res.best_f)
    assert all(np.isfinite(h["best"]) for h in res.history)


def test_a_tie_keeps_the_older_best():
    seen = []

    def flat(X):
        seen.append(np.array(X))
        return np.ones(len(X))

    res = optimize(Sphere(dim=3), "rcga", seed=0, population=9, generations=4, evaluator=flat, progress=False)
    np.testing.assert_array_equal(res.best_x, seen[0][0])
