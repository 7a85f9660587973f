"""The third round of bad inputs (issue 41), against the surfaces added after the second: scenes, landing gardens,
the flowers of ``Flight3D``, output folders, command names. Each command-line case ends in exit status 2 with one
sentence, within seconds, before anything is written or simulated (``tests/battery.py``); the Python cases raise one
:class:`~lifelike_mj.errors.UserError` naming the argument.

The classes: a loop that could not end (flowers that do not fit), geometry that cannot be (a flower under the
ground), a scene part's options parsed as the command line's (negative values, "did you mean", flags), every part
checked before the first runs, messages that say what is wrong (a missing file, a folder, a misspelt command), and
outputs that are not made in folders that do not exist.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from battery import check_python_refusal, check_refusal

from lifelike_mj.cli import main
from lifelike_mj.errors import UnknownName, UserError


def scene(*parts, duration_s=0.5, fps=30) -> dict:
    return {"format": "lifelike-mj/scene", "version": 1, "name": "t", "duration_s": duration_s, "fps": fps,
            "parts": [dict(p) for p in parts]}


BF = {"name": "one", "creature": "butterfly3d", "options": {"task": "level"}}
FISH = {"name": "pond", "creature": "fish", "options": {"fish": 2}}
SCENE = ["export", "scene", "s.json", "--out", "s.glb"]

CASES = [
    # --- flowers that cannot fit: refused before any draw, with the most that fit
    (["butterfly", "land3d", "--flowers", "50", "--size", "2"], "a 2 m square (--size) holds at most 4 flowers", {}),
    (["butterfly", "land3d", "--flowers", "200", "--size", "6"], "ask for at most 36, or a --size of at least", {}),
    # --- a scene part's options: the command line's names and checks
    (SCENE, "has no option 'wind_frm' (did you mean 'wind_from'?)",
     {"s.json": scene(dict(BF, options={"task": "level", "wind_frm": [-0.5, 0, 0]}))}),
    (SCENE, "--garden: must be a whole number from 0 to 500, got 'yes'",
     {"s.json": scene(dict(BF, options={"task": "level", "garden": "yes"}))}),
    (SCENE, "the scene sets 'overwrite' itself", {"s.json": scene(dict(BF, options={"overwrite": True}))}),
    (SCENE, "option 'garden' takes a value", {"s.json": scene(dict(BF, options={"garden": True}))}),
    (SCENE, "argument --wind-from: needs three numbers X,Y,Z in m/s, each within +-50",
     {"s.json": scene(dict(BF, options={"wind_from": [-60, 0, 0]}))}),
    (SCENE, "argument --speed: must be a number in [0.1, 5] m/s, got -1.0", {"s.json": scene(dict(BF, options={"speed": -1}))}),
    (SCENE, "--task 'lvl' is not one of level, turn, course (did you mean 'level'?)",
     {"s.json": scene(dict(BF, options={"task": "lvl"}))}),
    # --- every part checked, its recording planned, before the first part runs
    (SCENE, "part 'two': recording", {"s.json": scene(FISH, dict(FISH, name="two", options={"fish": 3000}),
                                                      duration_s=300, fps=60)}),
    (SCENE, "is not strict JSON (the key 'duration_s' is given twice in one object)",
     {"s.json": '{"format": "lifelike-mj/scene", "version": 1, "duration_s": 1, "duration_s": 2, "parts": []}'}),
    # --- messages that say what is wrong
    (SCENE, "scene file s.json does not exist", {}),
    (SCENE, "scene file s.json is a folder, not a file", {"s.json/": None}),
    (SCENE, "scene file s.json is not a JSON file (expecting value at line 1, column 6)", {"s.json": '{"a":'}),
    (["butterfly", "fly", "--controller", "c.json"], "controller file c.json does not exist", {}),
    (["butterfly", "flyy"], "lifelike-mj butterfly has no command 'flyy' (did you mean 'fly'?)", {}),
    (["exprt", "fish"], "lifelike-mj has no command 'exprt' (did you mean 'export'?)", {}),
    (["fish", "swim", "--sed", "3"], "lifelike-mj fish swim has no option '--sed' (did you mean '--seed'?)", {}),
    (["butterfly", "fly3d", "--task", "lvl"], "--task 'lvl' is not one of level, turn, course", {}),
    # --- outputs: no folder made silently on the way to a file, nor more than the folder asked for
    (["export", "fish", "--duration", "0.2", "--out", "a/b/x.glb"], "the folder a does not exist", {}),
    (["export", "fish", "--duration", "0.2", "--out", "/no_such_top_folder/x.glb"],
     "the folder /no_such_top_folder does not exist", {}),
    (["fish", "swim", "--duration", "1", "--out", "a/b"], "the folder a does not exist", {}),
    (["reproduce", "fish", "--out", "a/b"], "the folder a does not exist", {}),
]


@pytest.mark.parametrize("argv, needle, files", CASES, ids=[" ".join(c[0])[:60] + f" #{i}" for i, c in enumerate(CASES)])
def test_bad_input_is_one_sentence_and_exit_2(argv, needle, files, tmp_path, monkeypatch, capsys):
    check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys)


def test_a_scene_flag_takes_only_true_or_false(tmp_path, monkeypatch, capsys):
    """A flag (a ``store_true`` option of the part's command) takes only ``true`` or ``false``, an option with a
    value never a bool; on a parser of the command line's kind."""
    from lifelike_mj.cli.common import Parser
    from lifelike_mj.cli.scene import _tokens

    p = Parser(prog="t", add_help=False)
    p.add_argument("--shy", action="store_true")
    p.add_argument("--level", type=float, default=0.0)
    assert _tokens({"shy": True, "level": -0.5}, p, "x", "w") == ["--shy", "--level=-0.5"]
    assert _tokens({"shy": False}, p, "x", "w") == []
    with pytest.raises(UserError, match="option 'shy' is a flag: give true or false, got 'yes'"):
        _tokens({"shy": "yes"}, p, "x", "w")
    with pytest.raises(UserError, match="option 'level' takes a value"):
        _tokens({"level": True}, p, "x", "w")
    with pytest.raises(UnknownName, match="did you mean 'level'"):
        _tokens({"levl": 1}, p, "x", "w")


def test_a_scene_part_takes_negative_values_as_the_command_line_does(tmp_path, monkeypatch, capsys):
    """``"wind_from": [-0.5, 0, 0]`` is ``--wind-from -0.5,0,0``: the same wind as the command's."""
    from lifelike_mj.cli.scene import _parse_part

    args = _parse_part(dict(BF, options={"task": "level", "wind_from": [-0.5, 0, 0], "angle": -30}), scene(BF), "w")
    assert args.wind == (0.5, 0.0, 0.0) and args.angle == -30.0  # the 3D flight keeps the air's velocity
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.json").write_text(json.dumps(scene(dict(BF, options={"task": "level", "wind_from": [-0.5, 0, 0]}))))
    assert main(["export", "scene", "s.json", "--out", "s.glb", "--json"]) == 0
    made = json.loads(capsys.readouterr().out)
    assert made["parts"] == ["one"] and (tmp_path / "s.glb").exists()


def test_the_scene_sets_message_names_its_part_once(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "s.json").write_text(json.dumps(scene(dict(FISH, options={"duration": 3}))))
    assert main(SCENE) == 2
    err = capsys.readouterr().err
    assert err.count("part 'pond'") == 1 and "the scene sets 'duration' itself" in err, err


def test_flowers_that_cannot_fit_are_refused_from_python_and_crowded_ones_end():
    from lifelike_mj.butterfly.flight3d import Garden
    from lifelike_mj.butterfly.flight3d.flowers import SPACING_M, max_flowers, place_flowers

    with pytest.raises(UserError, match="n_flowers 40 cannot be met: a 6 m square \\(size_m\\) holds at most 36"):
        Garden(2, n_flowers=40, size_m=6.0)
    with pytest.raises(UserError, match="n 5 cannot be met"):
        place_flowers(0, 5, 2.0)
    assert max_flowers(2.0) == 4 and max_flowers(6.0) == 36 and max_flowers(8.0) == 56
    # crowded gardens that random draws alone would not finish (three in a 2 m square jam on these seeds)
    for seed, n, size in [(0, 36, 6.0), (1, 4, 2.0), (2, 3, 2.0), (3, 56, 8.0)]:
        t0 = time.perf_counter()
        b = place_flowers(seed, n, size)
        assert time.perf_counter() - t0 < 5.0
        d = np.sqrt(((b[:, None, :2] - b[None, :, :2]) ** 2).sum(-1)) + np.eye(n) * 1e9
        assert b.shape == (n, 3) and d.min() >= SPACING_M - 1e-9 and np.abs(b[:, :2]).max() <= size / 2 + 1e-9


def test_gardens_that_fit_are_drawn_as_before():
    """The bound changes nothing for a garden that random draws fill: the old unbounded sampler's flowers, bit for
    bit (written out here from the code of before)."""
    from lifelike_mj.butterfly.flight3d.flowers import place_flowers

    def before(seed, n, size_m, heights_m=0.5):
        rng = np.random.default_rng([seed, 1])
        pts: list = []
        while len(pts) < n:
            p = np.array([*rng.uniform(-size_m / 2, size_m / 2, 2), rng.uniform(-heights_m / 2, heights_m / 2)])
            if all(np.linalg.norm(p[:2] - q[:2]) >= 1.2 for q in pts):
                pts.append(p)
        return np.array(pts)

    for seed in range(20):
        for n, size in [(10, 6.0), (11, 6.0), (12, 8.0), (6, 4.0)]:
            assert np.array_equal(place_flowers(seed, n, size), before(seed, n, size))


PYTHON_CASES = [
    # geometry that cannot be
    (lambda f: f.Flight3D(flowers=[(0, 0, 0), (1, 0, -5)]), "flower 1's blossom at z = -5 m is not above the ground at -4 m"),
    (lambda f: f.Flight3D(flowers=[(0, 0, 0.01)], ground_m=0.0), "not above the ground at 0 m"),
    # a flag is a bool
    (lambda f: f.Flight3D(contact="no"), "contact must be True or False, got 'no'"),
    (lambda f: f.Flight3D(end_on_tumble=1), "end_on_tumble must be True or False, got 1"),
    (lambda f: f.Garden(2, land="false"), "land must be True or False, got 'false'"),
    # flowers that cannot fit, from Python: no hang
    (lambda f: f.Garden(2, n_flowers=200, size_m=2.0), "n_flowers 200 cannot be met: a 2 m square (size_m) holds at most 4"),
    (lambda f: f.place_flowers(0, 10, 2.0), "n 10 cannot be met"),
    (lambda f: f.Flight3D(params=5), "params must be ButterflyParams, got 5"),
]


@pytest.mark.parametrize("call, needle", PYTHON_CASES, ids=[c[1][:40] for c in PYTHON_CASES])
def test_geometry_that_cannot_be_is_refused(call, needle):
    from lifelike_mj.butterfly import flight3d

    check_python_refusal(lambda: call(flight3d), needle)


def test_a_usdz_package_is_written_without_warnings(tmp_path, monkeypatch, capfd):
    """usd-core's packager moved bare texture paths and warned that it could not resolve them; the file was right,
    the warning was not."""
    pytest.importorskip("pxr")
    import zipfile

    monkeypatch.chdir(tmp_path)
    assert main(["export", "fish", "--fish", "2", "--duration", "0.2", "--out", "f.usdz", "--quiet"]) == 0
    err = capfd.readouterr().err
    assert "Warning" not in err and "Failed to resolve" not in err, err
    names = zipfile.ZipFile(tmp_path / "f.usdz").namelist()
    assert names[0] == "stage.usdc" and any(n.startswith("textures/") and n.endswith(".png") for n in names), names


def test_the_documented_longest_window_is_allowed():
    """``--duration`` and ``--fps`` at their joint maximum: ten minutes at 60 frames per second is 36,001 frames with
    the first and the last, and is allowed; one frame more is not."""
    from lifelike_mj.export.poses import frames_of

    assert frames_of(600.0, 60.0) == 36_001 and frames_of(1200.0, 30.0) == 36_001
    with pytest.raises(UserError, match="asks for 36,002 frames; at most 36,001"):
        frames_of(600.0 + 1 / 60, 60.0)


@pytest.mark.parametrize("scene_text, needle", [
    ('{"format": "lifelike-mj/scene", "version": 1, "duration_s": 1, "parts": [{"name": "a", "creature": "fish", '
     '"options": {"n": null}}]}', "parts[0].options.n must be a text or a finite number or true or false or a list of "
                                  "numbers, got null"),
    ('{"format": "lifelike-mj/scene", "version": 1, "duration_s": 1, "parts": [{"name": "a", "creature": "fish", '
     '"follow": ["x", "x"]}]}', 'parts[0].follow must not list an item twice, got ["x", "x"]'),
    ('{"version": 1, "duration_s": 1, "parts": []}', 'it has no "format" key'),
])
def test_a_malformed_scene_is_named_in_the_files_own_words(scene_text, needle, tmp_path, monkeypatch, capsys):
    """The sentence speaks JSON (null, true, double quotes), not Python (None, True)."""
    check_refusal(SCENE, needle, {"s.json": scene_text}, tmp_path, monkeypatch, capsys)
