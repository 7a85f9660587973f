"""The fish against a hostile tester (issue 41): the largest tank the command line allows steps (MuJoCo's arena sized
from the scene); the group measures find neighbours with a k-d tree frame by frame, giving the numbers the all-pairs
measures gave, in memory that grows with the fish, not with their square; every argument of ``Tank`` and ``Aquarium``
is checked as strictly as the command line checks it (a bool a bool, a size three numbers within ``--tank``'s
bounds), in one sentence naming it, before anything is built; ``--tank`` says what it takes; ``--n`` and ``--fish``
(one option, two spellings) are refused together."""

from __future__ import annotations

import json
import math
import tracemalloc

import numpy as np
import pytest
from battery import check_refusal

from lifelike_mj.cli import main
from lifelike_mj.errors import UnknownName, UserError
from lifelike_mj.fish import Tank, load_preset, shoal
from lifelike_mj.fish import scene as fish_scene
from lifelike_mj.fish.aquarium import Aquarium
from lifelike_mj.fish.params import MAX_FISH, FishParams

NAN = math.nan


# ---- 1. the largest tank steps ------------------------------------------------------------------------------------


def test_the_arena_grows_with_the_scene_where_the_tank_s_own_is_too_small():
    """A base spec whose arena (256 kB) cannot hold the broad phase's lists of body pairs for 400 fish (641 kB): the
    scene is given what it needs (``arena_bytes``), and the tank steps."""
    spec = fish_scene.base_spec((3.0, 3.0, 1.0))
    spec.memory = 256 * 2**10
    from lifelike_mj.fish.sim import FISH_BLOCK, U_FISH

    sc = fish_scene.build_scene(400, (3.0, 3.0, 1.0), spec=spec, nuserdata=U_FISH + FISH_BLOCK * 400)
    assert sc.model.narena >= fish_scene.arena_bytes(401, 400) > 4 * 401 * 400
    tank = Tank(load_preset("school"), 400, seed=1, scene=sc)
    tank.step(3)
    assert tank.data.maxuse_stack > 256 * 2**10  # it needed more than the spec's own arena
    # the tank's own 64 MB holds a small tank: nothing changes there
    assert fish_scene.build_scene(10).model.narena == 64 * 2**20


def test_the_arena_s_size_changes_no_track():
    """Fish that touch, crowded (contacts every step), in an arena of 64 MB and of 512 MB: the same tracks, bit for
    bit (the arena only holds what MuJoCo computes)."""
    from lifelike_mj.fish.sim import FISH_BLOCK, U_FISH

    runs = []
    for memory in (64 * 2**20, 512 * 2**20):
        spec = fish_scene.base_spec((0.4, 0.4, 0.3))
        spec.memory = memory
        sc = fish_scene.build_scene(40, (0.4, 0.4, 0.3), spec=spec, nuserdata=U_FISH + FISH_BLOCK * 40)
        assert sc.model.narena == memory
        t = Tank(load_preset("school"), 40, seed=2, scene=sc)
        contacts = 0
        for _ in range(90):
            t.step(1)
            contacts = max(contacts, t.data.ncon)
        assert contacts > 0  # the fish touch: the arena holds contacts
        runs.append((t.data.qpos.copy(), t.data.qvel.copy()))
    assert all(np.array_equal(a, b) for a, b in zip(*runs, strict=True))


@pytest.mark.slow
def test_the_largest_tank_swims_and_exports(tmp_path, monkeypatch, capsys):
    """5,000 fish (the most ``--n`` takes): ``fish swim`` of the paper's ``B-D`` with every file, and ``export fish``
    of the ``school`` (fish that touch) each run to the end (before issue 41: ``mj_stackAlloc: out of memory``)."""
    monkeypatch.chdir(tmp_path)
    assert main(["fish", "swim", "--n", str(MAX_FISH), "--duration", "0.25", "--out", "swim", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["fish"] == MAX_FISH and summary["fish_outside_tank"] == 0
    assert summary["group"]["fish"] == MAX_FISH and summary["group"]["nn_distance_bl"]["median"] > 0
    assert (tmp_path / "swim" / "tracks.npz").stat().st_size > 0
    assert main(["export", "fish", "--preset", "school", "--n", str(MAX_FISH), "--duration", "0.1", "--fps", "20",
                 "--looks", "mjcf", "--out", "school.glb", "--json"]) == 0
    assert (tmp_path / "school.glb").read_bytes()[:4] == b"glTF"


# ---- 2. the group measures: the same numbers, memory that grows with the fish ------------------------------------


def _nearest_all_pairs(p: np.ndarray) -> np.ndarray:
    """The nearest-neighbour distance over every pair of fish at every sample at once (the measure before issue 41)."""
    T, F, _ = p.shape
    if F < 2:
        return np.full((T, F), np.nan)
    d = np.linalg.norm(p[:, :, None, :] - p[:, None, :, :], axis=-1)
    d[:, np.arange(F), np.arange(F)] = np.inf
    return d.min(axis=2)


def _largest_group_all_pairs(p: np.ndarray, link_m: float) -> np.ndarray:
    """The largest group by a search from each unlabelled fish in turn over the table of all pairs (before issue 41)."""
    F = p.shape[0]
    near = np.linalg.norm(p[:, None] - p[None], axis=-1) <= link_m
    label = np.full(F, -1)
    for s in range(F):
        if label[s] >= 0:
            continue
        label[s], stack = s, [s]
        while stack:
            i = stack.pop()
            for j in np.flatnonzero(near[i] & (label < 0)):
                label[j] = s
                stack.append(j)
    return np.flatnonzero(label == int(np.argmax(np.bincount(label, minlength=F))))


def _same(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and bool(np.all((a == b) | (np.isnan(a) & np.isnan(b))))


@pytest.mark.parametrize("tree_min", [1, 10**9], ids=["k-d tree", "all pairs in chunks"])
@pytest.mark.filterwarnings("ignore:invalid value encountered")
def test_the_neighbours_are_the_all_pairs_neighbours_bit_for_bit(tree_min, monkeypatch):
    """Random tracks (two fish at one place, a NaN, an infinity, groups in clumps) and a school's: the distances and
    groups of the all-pairs measures exactly, whichever way the neighbours are found, in chunks of any size."""
    monkeypatch.setattr(shoal, "TREE_MIN_FISH", tree_min)
    monkeypatch.setattr(shoal, "PAIR_CHUNK_BYTES", 4096)  # many chunks
    rng = np.random.default_rng(41)
    for trial in range(12):
        T, F = int(rng.integers(1, 12)), int(rng.integers(1, 70))
        p = rng.normal(size=(T, F, 3)) * [0.01, 1.0, 30.0][trial % 3]
        if F > 3:
            p[:, 1] = p[:, 0]
            p[T // 2, 2, 0] = NAN if trial % 2 else math.inf
        assert _same(shoal.nearest_neighbour_m(p), _nearest_all_pairs(p)), trial
        for link in (0.0, 0.2, 1.0, 3.0, -1.0, NAN):
            assert np.array_equal(shoal.largest_group(p[0], link), _largest_group_all_pairs(p[0], link)), (trial, link)
    r = Tank(load_preset("school"), 45, seed=4, size=(1.0, 1.0, 0.5)).record(duration_s=2.0)
    assert _same(shoal.nearest_neighbour_m(r.positions), _nearest_all_pairs(r.positions))
    for k in (0, 60, 120):
        for link in (0.1, 0.21, 0.5):
            assert np.array_equal(shoal.largest_group(r.positions[k], link),
                                  _largest_group_all_pairs(r.positions[k], link))


def test_the_pair_measures_stream_over_the_frames_with_the_same_numbers(monkeypatch):
    """``neighbour_frame`` and ``pair_quantities`` in chunks of a few frames: the same arrays as in one chunk."""
    r = Tank(load_preset("school"), 6, seed=3, size=(1.0, 1.0, 0.5)).record(duration_s=3.0)
    head = shoal.headings(shoal.velocities(r.times_s, r.positions), 0.01)
    whole = shoal.neighbour_frame(r.positions, head), shoal.pair_quantities(r.times_s, r.positions, 0.07, r.tank_m)
    monkeypatch.setattr(shoal, "PAIR_CHUNK_BYTES", 2048)
    chunked = shoal.neighbour_frame(r.positions, head), shoal.pair_quantities(r.times_s, r.positions, 0.07, r.tank_m)
    assert all(np.array_equal(a, b) for a, b in zip(whole[0], chunked[0], strict=True))
    assert whole[1].keys() == chunked[1].keys()
    assert all(np.array_equal(whole[1][k], chunked[1][k]) for k in whole[1])
    assert whole[0][0].shape[0] > 0


def test_the_memory_of_the_group_measures_grows_with_the_fish_not_their_square():
    """3,000 fish over 40 samples: the all-pairs measure held 40 x 3,000^2 x 3 differences (8.6 GB); frame by frame
    with a k-d tree, the arrays NumPy allocates stay under 16 MB (tracemalloc; 1 MB measured)."""
    import scipy.sparse.csgraph  # noqa: F401  (loaded before the count: a library's own memory is not the measure's)
    import scipy.spatial  # noqa: F401

    rng = np.random.default_rng(0)
    p = rng.uniform(0.0, 3.0, size=(40, 3000, 3))
    tracemalloc.start()
    try:
        nn = shoal.nearest_neighbour_m(p)
        g = shoal.largest_group(p[0], 0.08)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert nn.shape == (40, 3000) and np.all(nn > 0) and g.size >= 1
    assert peak < 16 * 2**20, f"{peak / 2**20:.0f} MB"


# ---- 3. every argument of Tank and Aquarium checked ----------------------------------------------------------------


@pytest.fixture(scope="module")
def tank():
    return Tank(n_fish=2, seed=0)


@pytest.fixture
def nothing_built(monkeypatch):
    """A scene built during the call fails the test: every argument is checked before any work."""
    def refuse(*a, **k):
        raise AssertionError("a scene was built before the arguments were checked")

    monkeypatch.setattr("lifelike_mj.fish.sim.build_scene", refuse)


TANK_BAD = [
    ({"params": "B-D"}, "params must be a fish preset (a FishParams"),
    ({"params": {"P_a": 4.0}}, "params must be a fish preset"),
    ({"n_fish": "10"}, "the number of fish must be a whole number from 1 to 5,000 (n_fish), got '10'"),
    ({"n_fish": True}, "(n_fish), got True"),
    ({"n_fish": 2.0}, "(n_fish), got 2.0"),
    ({"n_fish": 0}, "(n_fish), got 0"),
    ({"n_fish": MAX_FISH + 1}, "from 1 to 5,000 (n_fish), got 5001"),
    ({"seed": -1}, "seed must be a whole number from 0 to 4294967295"),
    ({"seed": 2**32}, "seed must be a whole number from 0 to 4294967295"),
    ({"seed": "3"}, "seed must be a whole number"),
    ({"size": (3.0, 3.0, 1e300)}, "size must have every side of the tank at most 100 m"),
    ({"size": (100.001, 1.0, 1.0)}, "at most 100 m"),
    ({"size": (3.0, 3.0, 0.1)}, "at least 0.175 m (2.5 body lengths)"),
    ({"size": ("3", "3", "1")}, "size must be three positive lengths L,D,H in m (length, depth, height)"),
    ({"size": "3,3,1"}, "size must be three positive lengths L,D,H in m"),
    ({"size": (3.0, 3.0)}, "three positive lengths"),
    ({"size": (3.0, 3.0, 1.0, 1.0)}, "three positive lengths"),
    ({"size": (3.0, NAN, 1.0)}, "three positive lengths"),
    ({"size": (3.0, -3.0, 1.0)}, "three positive lengths"),
    ({"size": 3.0}, "three positive lengths"),
    ({"scene": "tank"}, "scene must be a FishScene"),
    ({"mu_policy": 3}, "mu_policy must be a function of the tank"),
    ({"push_policy": "away"}, "push_policy must be a function of the tank"),
]


@pytest.mark.parametrize("kw, words", TANK_BAD, ids=[f"{k}={v!r}" for d, _ in TANK_BAD for k, v in d.items()])
def test_a_bad_tank_argument_is_one_sentence_naming_it_before_anything_is_built(kw, words, nothing_built):
    with pytest.raises(UserError) as info:
        Tank(**kw)
    assert words in str(info.value) and "\n" not in str(info.value), str(info.value)


def test_arguments_in_the_wrong_place_are_named(nothing_built):
    """What a user does by mistake: the count first, the size in the seed's place, the params for the size."""
    with pytest.raises(UserError, match=r"params must be a fish preset .* got 10\."):
        Tank(10)
    with pytest.raises(UserError, match=r"seed must be a whole number from 0 to 4294967295, got \(3, 3, 1\)"):
        Tank(None, 10, (3, 3, 1))
    with pytest.raises(UserError, match=r"size must be three positive lengths .* got a FishParams"):
        Tank(None, 10, 0, FishParams())


def test_scene_and_size_together_are_refused(tank):
    with pytest.raises(UserError, match="give the tank either as scene or as size, not both"):
        Tank(n_fish=2, scene=tank.scene, size=(3.0, 3.0, 1.0))


def test_the_python_api_takes_the_command_line_s_largest_and_smallest_tank():
    from lifelike_mj.cli import fish as cli_fish

    assert cli_fish.MAX_TANK_SIDE_M == fish_scene.MAX_TANK_SIDE_M
    for size in ((100.0, 1.0, 1.0), (0.175, 0.175, 0.175)):
        assert Tank(n_fish=1, size=size).scene.size == size


def test_record_checks_its_chunks_and_its_progress_flag(tank):
    import signal

    def hang(signum, frame):
        raise AssertionError("record(chunk_steps=0) did not return (chunks of no step never end)")

    old = signal.signal(signal.SIGALRM, hang)
    signal.alarm(20)
    try:
        with pytest.raises(UserError, match="chunk_steps must be a whole number of at least 1, got 0"):
            tank.record(duration_s=1.0, chunk_steps=0)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
    with pytest.raises(UserError, match="progress must be True or False, got 'no'"):
        tank.record(n_steps=2, progress="no")


AQUARIUM_BAD = [
    (lambda t: Aquarium(load_preset("B-D")), UserError, r"tank must be a fish Tank .* got a FishParams\."),
    (lambda t: Aquarium(None), UserError, r"tank must be a fish Tank .* got None\."),
    (lambda t: Aquarium((3.0, 3.0, 1.0)), UserError, r"tank must be a fish Tank .* got \(3\.0, 3\.0, 1\.0\)\."),
    (lambda t: Aquarium(t, "yes"), UserError, "cascade must be True or False, got 'yes'"),
    (lambda t: Aquarium(t, cascade=1), UserError, "cascade must be True or False, got 1"),
    (lambda t: Aquarium(t, compete="no"), UserError, "compete must be True or False, got 'no'"),
    (lambda t: Aquarium(t, True, t), UserError, "compete must be True or False, got <.*Tank"),
    (lambda t: Aquarium(t, cascad=True), UnknownName, "did you mean 'cascade'"),
    (lambda t: Aquarium(tank=t, tnak=t), UnknownName, "did you mean 'tank'"),
]


@pytest.mark.parametrize("make, kind, words", AQUARIUM_BAD, ids=[str(i) for i in range(len(AQUARIUM_BAD))])
def test_a_bad_aquarium_argument_is_one_sentence_naming_it(make, kind, words, tank):
    with pytest.raises(kind, match=words) as info:
        make(tank)
    assert "\n" not in str(info.value)


def test_the_aquarium_takes_real_bools(tank):
    a = Aquarium(Tank(n_fish=2, seed=1), cascade=np.bool_(True), compete=False)
    assert a.cascade is True and a.compete is False


# ---- 4. the command line's messages ----------------------------------------------------------------------------


@pytest.mark.parametrize("argv, needle", [
    (["fish", "swim", "--tank", "3,,1"], "--tank: expected three lengths L,D,H in m (length, depth, height"),
    (["fish", "swim", "--tank", "a,b,c"], "got 'a,b,c'"),
    (["fish", "swim", "--tank", "3;3;1"], "got '3;3;1'"),
    (["fish", "swim", "--tank", "3,3,1e300"], "--tank: must have every side of the tank at most 100 m, got '3,3,1e300'"),
    (["fish", "swim", "--tank", "3,3,-1"], "--tank: must be three positive lengths L,D,H in m"),
    (["fish", "swim", "--n", "10", "--fish", "5"], "give the number of fish once, as --n or --fish, not both"),
    (["fish", "swim", "--fish", "5", "--n", "5"], "as --fish or --n, not both (got --fish 5 and --n 5)"),
    (["export", "fish", "--fish", "5", "--n", "6", "--out", "f.glb"], "not both"),
    (["render", "fish", "--n", "2", "--fish", "3", "--out", "f.mp4"], "not both"),
])
def test_the_command_line_says_what_it_takes(argv, needle, tmp_path, monkeypatch, capsys):
    check_refusal(argv, needle, {}, tmp_path, monkeypatch, capsys)


def test_one_spelling_of_the_fish_count_is_taken_and_the_same_twice_keeps_the_last(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    for argv, n in ((["--fish", "2"], 2), (["--n", "3"], 3), (["--n", "2", "--n", "3"], 3)):
        assert main(["fish", "swim", *argv, "--duration", "0.05", "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["fish"] == n


# ---- 5. fuzzed: no exception but a one-sentence refusal ---------------------------------------------------------

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

JUNK = st.one_of(st.none(), st.booleans(), st.text(max_size=6), st.integers(-(10**20), 10**20),
                 st.floats(), st.tuples(st.floats(), st.floats(), st.floats()),
                 st.lists(st.one_of(st.floats(-5, 5), st.text(max_size=2)), max_size=4),
                 st.dictionaries(st.text(max_size=3), st.integers(), max_size=2), st.just(np.float64(NAN)),
                 st.just(np.array([3.0, 3.0, 1.0])), st.just(np.int64(2)), st.just("3,3,1"), st.just(FishParams()))
SIZES = st.one_of(st.none(), st.tuples(*[st.floats(0.1, 120.0)] * 3), st.tuples(*[st.sampled_from(
    [0.175, 1.0, 100.0, 100.0001, 0.17, 1e300, -1.0, 0.0, NAN, math.inf, "1", None])] * 3), JUNK)
COUNTS = st.one_of(st.integers(1, 3), st.integers(-3, 0), st.just(MAX_FISH + 1), st.integers(10**6, 10**30), JUNK)
FLAGS = st.one_of(st.booleans(), st.just(np.bool_(True)), JUNK)
FUZZ = settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])


@FUZZ
@given(params=st.one_of(st.none(), st.just(FishParams()), JUNK), n_fish=COUNTS, seed=st.one_of(st.integers(0, 9), JUNK),
       size=SIZES, policy=st.one_of(st.none(), st.just(lambda t: None), JUNK), cascade=FLAGS, compete=FLAGS)
def test_fuzzed_tank_and_aquarium_arguments_build_or_are_refused_in_one_sentence(params, n_fish, seed, size, policy,
                                                                                  cascade, compete):
    try:
        t = Tank(params, n_fish, seed, size, mu_policy=policy)
        a = Aquarium(t, cascade, compete)
    except (UserError, UnknownName) as e:
        assert "\n" not in str(e) and str(e).endswith("."), str(e)
        return
    assert isinstance(cascade, (bool, np.bool_)) and isinstance(compete, (bool, np.bool_))
    a.step(1)


@FUZZ
@given(args=st.lists(st.one_of(JUNK, st.just("tank"), st.integers(1, 3)), max_size=5))
def test_fuzzed_positional_arguments_in_any_slot_are_refused_in_one_sentence(args, tank):
    args = [tank if isinstance(a, str) and a == "tank" else a for a in args]
    for make in (Tank, Aquarium):
        try:
            made = make(*args)
        except (UserError, UnknownName) as e:
            assert "\n" not in str(e), str(e)
        except TypeError as e:  # more positional arguments than the constructor has: Python's own
            assert "positional argument" in str(e), str(e)
        else:
            made.step(1)
