"""The 3D butterfly against a hostile user (issue 41): its controller files are refused by their size and their shape
before their numbers are read one by one; an evolution of a behaviour its tasks never fly, or whose candidates all
score the same, writes nothing; every option of the 3D commands is checked before any flight begins; flags are real
bools; and NaN, infinities, wrong types, unknown keys, folders, missing, empty and foreign files are one sentence each
(exit status 2 on the command line, a :class:`~lifelike_mj.errors.UserError` from Python).

The command-line cases run through ``tests/battery.py``'s ``check_refusal``: exit 2, one sentence holding the needle, no
traceback, within 10 s, nothing written."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from battery import check_refusal

from lifelike_mj.butterfly.flight3d import controllers as c3
from lifelike_mj.butterfly.flight3d import evolution as ev
from lifelike_mj.butterfly.flight3d import flight as flight3d_flight
from lifelike_mj.butterfly.flight3d.tasks import level
from lifelike_mj.errors import UserError

MONARCH = c3.load_controller("monarch").to_dict()
N = c3.n_weights(MONARCH["layers"])
FLY3D = ["butterfly", "fly3d", "--duration", "0.05", "--controller", "c.json"]
TINY = ["--generations", "1", "--population", "4", "--duration", "0.01"]


def _evolve(*args, **kw):
    """:func:`~lifelike_mj.butterfly.flight3d.evolution.evolve` on the smallest budget (so that a check removed shows at
    once, not after an evolution)."""
    return ev.evolve(*args, **{"generations": 1, "population": 4, "duration_s": 0.01, "progress": False, **kw})


def ctrl(**changes) -> dict:
    """The shipped monarch's file with ``changes`` (``None``: the key removed)."""
    d = json.loads(json.dumps(MONARCH))
    for k, v in changes.items():
        if v is None:
            d.pop(k, None)
        else:
            d[k] = v
    return d


def _with_weights_text(n: int) -> str:
    """The monarch's file, compact, its flight network given ``n`` weights (zeros): written as text, at once."""
    head = json.dumps(ctrl(weights=[]), separators=(",", ":"))
    return head.replace('"weights":[]', '"weights":[' + ",".join(["0"] * n) + "]", 1)


# ---- 1. size and shape before the numbers ---------------------------------------------------------------------------


def test_a_file_of_millions_of_weights_is_refused_by_their_count_at_once(tmp_path, monkeypatch, capsys):
    """The tester's 19 MB file: 9.4 million weights for a 99-weight network, refused in well under 10 s (it took a
    minute when every number was checked first)."""
    text = _with_weights_text(9_400_000)
    assert 18e6 < len(text) < c3.MAX_FILE_BYTES
    most = c3.n_weights([c3.N_OBS, *[c3.MAX_WIDTH] * (c3.MAX_LAYERS - 2), c3.N_ACT])
    check_refusal(FLY3D, f"weights must have at most {most} numbers, got 9400000", {"c.json": text}, tmp_path,
                  monkeypatch, capsys)


def test_weights_beyond_the_networks_shape_are_counted_before_their_numbers_are_checked():
    """Within the file format's bound, a network's weights beyond what its layers need (plus one) are never checked
    number by number: their count is refused first (a bad number beyond the shape is not what is reported)."""
    w = [0.0] * 200_000
    w[150_000] = "x"
    with pytest.raises(UserError, match=f"layers \\[10, 9\\] need {N} finite weights, each within \\+-1e\\+06, got 200000"):
        c3.controller_from_dict(ctrl(weights=w))
    modes = {"land": {"weights": w}}
    with pytest.raises(UserError, match=f"the land behaviour needs {N} finite weights .* got 200000"):
        c3.controller_from_dict(ctrl(modes=modes))
    # a bad number within the shape is still named as before, ahead of the count
    with pytest.raises(UserError, match=r"weights\[0\] must be a number in \[-1e\+06, 1e\+06\], got 'x'"):
        c3.controller_from_dict(ctrl(weights=["x"] + [0.0] * N))


def test_the_largest_legitimate_controller_loads_and_a_larger_file_is_refused_by_its_size(tmp_path, monkeypatch,
                                                                                           capsys):
    """MAX_FILE_BYTES is derived from the largest legitimate controller: a flight network of the most layers of the
    widest neurons, both behaviour networks, every weight as long as a float's text can be, written as lifelike-mj
    writes it, with a large provenance; that file (over the 20 MB of other JSON files) loads. One byte more than the
    bound is refused by its size before it is read: the file, its size and the limit in one sentence."""
    from lifelike_mj.io import write_json

    layers = [c3.N_OBS, *[c3.MAX_WIDTH] * (c3.MAX_LAYERS - 2), c3.N_ACT]
    longest = -2.2250738585072014e-308  # 24 characters
    assert len(repr(longest)) == 24
    w = np.full(c3.n_weights(layers), longest)
    big = c3.Controller3D(layers, w, modes={"land": {"weights": w}, "take_off": {"weights": w}},
                          provenance={"fitness_history": ["x" * 60] * 20_000})
    path = write_json(tmp_path / "big.json", big.to_dict())
    assert 20_000_000 < path.stat().st_size <= c3.MAX_FILE_BYTES
    again = c3.load_controller(path)
    assert np.array_equal(again.weights, w) and np.array_equal(again.mode_weights("take_off"), w)
    path.unlink()
    with open(tmp_path / "c.json", "wb") as fh:  # sparse: no disk is used
        fh.truncate(c3.MAX_FILE_BYTES + 1)
    check_refusal(FLY3D, f"c.json is {(c3.MAX_FILE_BYTES + 1) / 1e6:.1f} MB, larger than any 3D controller file can be",
                  {}, tmp_path, monkeypatch, capsys)


# ---- 2. an evolution that cannot learn writes nothing ---------------------------------------------------------------


@pytest.mark.parametrize("argv, needle", [
    (["--mode", "land", "--tasks", "steer"], "the land behaviour (--mode land) flies only on landing tasks, and the task "
                                             "set 'steer' has none: evolve it on a task set with landings (garden, "
                                             "landings, landings12)"),
    (["--mode", "land", "--tasks", "agile", "--take-off"], "the task set 'agile' has none"),
    (["--mode", "take_off", "--tasks", "landings"], "the take_off behaviour (--mode take_off) flies only after a "
                                                    "take-off, and no flight of the task set 'landings' takes off: add "
                                                    "take_off=True (--take-off)"),
])
def test_a_behaviour_its_task_set_never_flies_is_refused_before_any_work(argv, needle, tmp_path, monkeypatch, capsys):
    check_refusal(["butterfly", "evolve3d", "--start", "monarch", *argv, *TINY, "--out", "e.json"], needle, {}, tmp_path,
                  monkeypatch, capsys)


def test_the_same_from_python_names_the_tasks_given():
    m = c3.load_controller("monarch")
    with pytest.raises(UserError, match="flies only on landing tasks, and the tasks given have none"):
        _evolve((level(1.0),), "never.json", start=m, mode="land")
    with pytest.raises(UserError, match="flies only after a take-off, and no flight of the tasks given"):
        ev.FlightProblem3D((level(1.0),), m, duration_s=0.01, mode="take_off")
    assert ev.exercising_sets("land") == ["garden", "landings", "landings12"]


def test_an_evolution_whose_candidates_all_score_the_same_writes_nothing(tmp_path, monkeypatch, capsys):
    """Landing flights of 0.01 s never come near a flower, so the land network never flies: every candidate scores the
    same: from Python a UserError, from the command line exit 2 with the sentence; neither leaves the controller or the
    checkpoint behind. (The Python run comes first: it also compiles the flight's kernels, which a fresh checkout
    compiles once, in about 40 s, so that the command's own time is what the battery bounds.)"""
    with pytest.raises(UserError, match="every one of the 3 candidates of this evolution scored 1.2218e-05"):
        _evolve(ev.TASK_SETS["landings"](), tmp_path / "py.json", optimizer="rcga", population=3,
                start=c3.load_controller("monarch"), mode="land")
    assert list(tmp_path.iterdir()) == []
    check_refusal(["butterfly", "evolve3d", "--quiet", "--optimizer", "rcga", "--population", "3", "--generations", "1",
                   "--duration", "0.01", "--start", "monarch", "--mode", "land", "--tasks", "landings", "--out", "e.json"],
                  "every one of the 3 candidates of this evolution scored 1.2218e-05: changing its land network changed no "
                  "score (are its flights, 0.01 s each, long enough to fly it?), so nothing was written.", {}, tmp_path,
                  monkeypatch, capsys)
    assert list(tmp_path.iterdir()) == []


def test_an_evolution_whose_candidates_differ_is_written(tmp_path):
    """The refusal is no blanket: a take-off network flown from a perch changes the scores, and is written."""
    res, out = ev.evolve(ev.TASK_SETS["steer"](), tmp_path / "t.json", start=c3.load_controller("monarch"),
                         mode="take_off", take_off=True, generations=1, population=4, duration_s=0.05, progress=False)
    assert out is not None and (tmp_path / "t.json").is_file()
    assert len({h["best"] for h in res.history}) == 1 and res.history[0]["mean"] != res.history[0]["best"]


def test_all_same_reads_the_candidates_seen_and_the_earlier_generations_records():
    class Const:
        problem = None

        def __call__(self, X):
            return np.full(len(X), 0.25)

    s = ev._Spread(Const())
    assert s.all_same([]) is None  # nothing seen, nothing recorded
    s(np.zeros((4, 2)))
    mean4 = float(np.mean(np.full(4, 0.25)))
    assert s.all_same([{"best": 0.25, "mean": mean4}]) == 0.25
    assert s.all_same([{"best": 0.25, "mean": 0.2}, {"best": 0.25, "mean": mean4}]) is None  # an earlier session differed
    assert s.all_same([{"best": 0.3, "mean": 0.3}, {"best": 0.3, "mean": mean4}]) is None
    other = ev._Spread(lambda X: np.array([0.1, 0.2, math.nan, 0.2])[: len(X)])
    other(np.zeros((4, 2)))
    assert other.all_same([{"best": 0.2, "mean": -math.inf}]) is None
    resumed = ev._Spread(Const())  # a resumed run that was finished: only its records
    assert resumed.all_same([{"best": 0.5, "mean": 0.5}, {"best": 0.5, "mean": 0.5}]) == 0.5
    assert resumed.all_same([{"best": 0.5, "mean": 0.5}, {"best": 0.5, "mean": 0.4}]) is None


# ---- 3. every option before any flight ------------------------------------------------------------------------------

FAST = {"c.json": ctrl(base={**MONARCH["base"], "frequency_hz": 50.0})}


@pytest.mark.parametrize("argv, needle, files", [
    (["butterfly", "measure3d", "--controller", "monarch", "--dt", "0.0125", "--settle", "0", "--window", "0.5"],
     "--dt 0.0125 s does not resolve the 0.0980392 s wing beat: it must be at most 1/8 of it", {}),
    (["butterfly", "measure3d", "--dt", "0.0125", "--settle", "0", "--window", "0.5"],  # designed: up to 11 Hz
     "--dt 0.0125 s does not resolve the 0.0909091 s wing beat: it must be at most 1/8 of it", {}),
    (["butterfly", "assess3d", "--dt", "0.0125", "--duration", "7", "--courses", "1"], "--dt 0.0125 s does not resolve", {}),
    (["butterfly", "garden", "--dt", "0.0125", "--n", "1", "--duration", "0.1"], "--dt 0.0125 s does not resolve", {}),
    (["butterfly", "evolve3d", "--dt", "0.0125", *TINY, "--out", "e.json"], "argument --dt: must be a number in [1e-05, "
                                                                            "0.01] s", {}),
    (["butterfly", "evolve3d", "--start", "c.json", "--dt", "0.005", *TINY, "--out", "e.json"],
     "--dt 0.005 s does not resolve the 0.02 s wing beat", FAST),
    (["butterfly", "measure3d", "--controller", "c.json", "--dt", "0.005"], "--dt 0.005 s does not resolve", FAST),
])
def test_a_time_step_too_coarse_for_the_wing_beat_is_refused_before_the_flight_stage(argv, needle, files, tmp_path,
                                                                                      monkeypatch, capsys):
    """It was refused only once the flight stage had begun (measure3d, assess3d), or after the garden had flown and
    diverged; an evolution flew it."""
    check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys)


def test_an_evolution_refuses_a_time_step_its_start_cannot_fly():
    fast = c3.controller_from_dict(FAST["c.json"])
    with pytest.raises(UserError, match="dt_s 0.005 s does not resolve the 0.02 s wing beat"):
        ev.FlightProblem3D((level(1.0),), fast, dt_s=0.005)
    assert flight3d_flight.check_time_step(0.0024, 50.0) == 0.0024


# ---- 4. flags are bools ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("flag", ["natural", "take_off", "speed_input", "resume", "progress", "overwrite"])
@pytest.mark.parametrize("value", ["false", "no", 0, 1, None])
def test_evolve_takes_only_real_bools_as_flags(flag, value, tmp_path):
    with pytest.raises(UserError, match=f"{flag} must be True or False, got {value!r}"):
        _evolve(None, tmp_path / "e.json", **{flag: value})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("flag", ["natural", "take_off"])
def test_the_flight_problem_takes_only_real_bools_as_flags(flag):
    with pytest.raises(UserError, match=f"{flag} must be True or False, got 'no'"):
        ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), **{flag: "no"})
    assert getattr(ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), **{flag: np.True_}), flag) is True


@pytest.mark.parametrize("flag", ["contact", "end_on_tumble"])
def test_a_3d_flight_takes_only_real_bools_as_flags(flag):
    from lifelike_mj.butterfly.flight3d.flight import Flight3D

    with pytest.raises(UserError, match=f"{flag} must be True or False, got 'no'"):
        Flight3D(**{flag: "no"})


# ---- 5. the rest of a hostile user's inputs -------------------------------------------------------------------------

PLANAR = {"format": "lifelike-mj/butterfly-controller", "type": "constant", "parameters": {"phi_deg": 0}}


@pytest.mark.parametrize("argv", [FLY3D, ["butterfly", "land3d", "--controller", "c.json", "--flowers", "2"],
                                  ["butterfly", "measure3d", "--controller", "c.json"],
                                  ["butterfly", "assess3d", "--controller", "c.json"],
                                  ["butterfly", "evolve3d", "--start", "c.json", *TINY, "--out", "e.json"]],
                         ids=["fly3d", "land3d", "measure3d", "assess3d", "evolve3d"])
@pytest.mark.parametrize("needle, content", [
    ("c.json is a folder, not a file", None),
    ("3D controller file c.json does not exist", "missing"),
    ("3D controller file c.json is not a JSON file", ""),
    ("3D controller file c.json is not a JSON file", "x,y\n1,2\n"),
    ("not strict JSON (NaN", json.dumps(ctrl()).replace('"weights": [', '"weights": [NaN, ', 1)),
    ("must be a number in [-1e+06, 1e+06], got inf", json.dumps(ctrl()).replace('"weights": [', '"weights": [1e999, ', 1)),
    ("file c is not a 3D controller file (its format is \"lifelike-mj/butterfly-controller\"", PLANAR),
    ("file c is not a 3D controller file: it holds a JSON list", [1, 2]),
    ("modes.take_off has an unknown key 'from_m'",
     ctrl(modes={"take_off": {"weights": [0.0] * N, "from_m": 1.0}})),
    ("has an unknown key 'wieghts' (did you mean 'weights'?)", {**ctrl(weights=None), "wieghts": [0.0] * N}),
    ("modes.take_off.for_s must be a number in (0, 100], got -1", ctrl(modes={"take_off": {"weights": [0.0] * N,
                                                                                          "for_s": -1}})),
    (f"the take_off behaviour needs {N} finite weights", ctrl(modes={"take_off": {"weights": [0.0] * (N + 1)}})),
    ("base.frequency_hz must be a number in (0, 100], got 1e+300", ctrl(base={**MONARCH["base"], "frequency_hz": 1e300})),
    ("every must be a whole number from 1 to 12,000, got -1", ctrl(every=-1)),
    ("layers must be whole numbers running from 10 or 11 inputs to 9 outputs", ctrl(layers=[9, 9])),
    ("weights[3] must be a number in [-1e+06, 1e+06], got '0.1'", ctrl(weights=[0.0] * 3 + ["0.1"] + [0.0] * (N - 4))),
])
def test_a_hostile_controller_file_is_one_sentence_on_every_3d_command(argv, needle, content, tmp_path, monkeypatch,
                                                                        capsys):
    files = {"c.json/": ""} if content is None else ({} if content == "missing" else {"c.json": content})
    check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys)


@pytest.mark.parametrize("call, needle", [
    (lambda: c3.Controller3D([10, 9], None), "the weights must be numbers, got None"),
    (lambda: c3.Controller3D([10, 9], "0" * N), "the weights must be numbers"),
    (lambda: c3.Controller3D([10, 9], [1j] * N), r"the weights must be numbers, got \[1j, 1j, 1j, 1j, 1j, 1j, \.\.\.\]"),
    (lambda: c3.Controller3D([10, 9], [math.inf] * N), f"need {N} finite weights, .*, got {N} with one beyond"),
    (lambda: c3.Controller3D([10, 9], [0.0] * N, provenance=[1, 2]), "provenance is a mapping"),
    (lambda: c3.Controller3D([10, 9], [0.0] * N, name=5), "name is a text, got 5"),
    (lambda: c3.Controller3D([10] + [8] * 1_000_000 + [9], []), r"at most 6 layers .* got \[10, 8, 8, 8, 8, 8, \.\.\.\]"),
    (lambda: c3.Controller3D([10, 9], [0.0] * N, modes={"land": {"weights": None}}),
     "the land behaviour's weights must be numbers"),
    (lambda: c3.load_controller("monarch").mode_weights("fly"), "unknown behaviour 'fly'; known: land, take_off"),
    (lambda: c3.controller_from_dict(None), "it holds a JSON NoneType, not an object"),
    (lambda: c3.withdrawn_file("../../../controllers/butterfly3d/monarch"), "no withdrawn 3D controller '../../../controllers"),
    (lambda: _evolve("steer", "e.json"), r"tasks are Task3D objects .* TASK_SETS\['steer'\]\(\)\), got 'steer'"),
    (lambda: _evolve("landings", "e.json", start=c3.load_controller("monarch"), mode="land"),
     r"tasks are Task3D objects .* TASK_SETS\['landings'\]\(\)\), got 'landings'"),
    (lambda: _evolve([1, 2], "e.json"), r"tasks are Task3D objects .* got \[1, 2\]"),
    (lambda: _evolve(None, "e.json", start="monarch"), r"start is a 3D controller .* got 'monarch'"),
    (lambda: _evolve(None, "e.json", layers="10,9"), "layers must be whole numbers running from 10 or 11"),
    (lambda: _evolve(None, "e.json", layers=None), "layers must be whole numbers running from 10 or 11"),
    (lambda: _evolve(None, 5), "out is the path of a file"),
    (lambda: _evolve(None, "e.json", checkpoint=5), "checkpoint is the path of a file"),
    (lambda: _evolve(None, "e.json", on_generation=5), "on_generation is a function"),
    (lambda: _evolve(None, "e.json", task_set=5), "task_set is the name"),
    (lambda: _evolve(None, "e.json", start=c3.load_controller("monarch"), mode="take_off", take_off=True,
                       reach=math.nan), "for_s must be a number in \\(0, 100\\] s, got nan"),
    (lambda: ev.FlightProblem3D([level(1.0), "level"], c3.load_controller("monarch")), "tasks are Task3D objects"),
    (lambda: ev.FlightProblem3D((level(1.0),), "monarch"), "the template is a 3D controller"),
    (lambda: ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), params={}), "params is a ButterflyParams"),
    (lambda: ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), force_law="tip"), "force_law is"),
    (lambda: ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), n_strips=0), "n_strips"),
    (lambda: ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), mode="fly"), "mode is '' .* got 'fly'"),
    (lambda: ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), prior=[math.nan] * N),
     f"the prior must be the network's {N} weights"),
    (lambda: ev.FlightProblem3D((level(1.0),), c3.load_controller("monarch"), prior=[0.0] * 3),
     f"the prior must be the network's {N} weights"),
])
def test_hostile_python_inputs_are_one_sentence_before_any_work(call, needle, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(UserError, match=needle):
        call()
    assert list(tmp_path.iterdir()) == []


def test_a_numpy_prior_is_taken_as_its_weights():
    m = c3.load_controller("monarch")
    p = ev.FlightProblem3D((level(1.0),), m, prior=np.asarray(m.weights))
    assert p.prior == tuple(float(v) for v in m.weights)
    assert p.fingerprint() == ev.FlightProblem3D((level(1.0),), m).fingerprint()
