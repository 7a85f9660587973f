"""The command line: documented keys, and bad input as one sentence with exit status 2."""

import argparse
import json
import subprocess
import sys

import pytest

from lifelike_mj.butterfly import flight3d
from lifelike_mj.cli import main


def run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_speed_limit_json(capsys):
    code, out, _ = run(capsys, "butterfly", "speed-limit", "--body-area-cm2", "1.53", "--json")
    assert code == 0 and json.loads(out)["speed_limit_cm_s"] == 380
    code, out, _ = run(capsys, "butterfly", "speed-limit", "--json")
    assert json.loads(out)["speed_limit_cm_s"] == 438


def test_forces_json(capsys):
    code, out, _ = run(capsys, "butterfly", "forces", "--json")
    assert code == 0 and json.loads(out)["closed_form_max_rel_error"] < 1e-12


def test_fly_json_and_out(capsys, tmp_path):
    code, out, _ = run(capsys, "butterfly", "fly", "--controller", "simple_rule", "--duration", "12", "--json",
                       "--out", str(tmp_path), "--phi-up-deg", "14")
    assert code == 0
    d = json.loads(out)
    for key in ("final_altitude_m", "min_altitude_m", "mean_forward_speed_cm_s", "settled_altitude_min_m",
                "settled_altitude_max_m", "settled_forward_speed_cm_s"):
        assert key in d
    assert d["settled_altitude_max_m"] > d["settled_altitude_min_m"]
    for name in ("trajectory.npz", "trajectory.csv", "flight.png", "summary.json"):
        assert (tmp_path / name).stat().st_size > 0
    assert not list(tmp_path.glob(".*"))  # no temporary files left behind


def test_fly3d_in_gusty_wind_json_and_out(capsys, tmp_path):
    code, out, _ = run(capsys, "butterfly", "fly3d", "--controller", str(flight3d.withdrawn_file("wind")), "--task",
                       "course", "--seed", "101",
                       "--wind", "1,0,0", "--gusts", "0.5", "--vertical-gusts", "0.25", "--duration", "3", "--json",
                       "--out", str(tmp_path / "f"))
    assert code == 0
    s = json.loads(out)
    assert s["controller"] == "wind" and 0.0 < s["distance_m"] <= s["path_length_m"] and s["waypoints_passed"] >= 1
    assert {p.name for p in (tmp_path / "f").iterdir()} >= {"paths.png", "path.csv", "summary.json"}


def test_fly_mujoco_backend(capsys):
    code, out, _ = run(capsys, "butterfly", "fly", "--controller", "simple_rule", "--backend", "mujoco",
                       "--duration", "2", "--json")
    assert code == 0 and json.loads(out)["backend"] == "mujoco"


def test_compare_json(capsys):
    code, out, _ = run(capsys, "butterfly", "compare", "--controller", "simple_rule", "--duration", "5", "--json")
    d = json.loads(out)
    assert code == 0 and {"max_altitude_diff_m", "max_forward_diff_m"} <= d.keys()


@pytest.mark.parametrize(
    "argv",
    [
        ["butterfly", "fly", "--controller", "no_such_controller"],
        ["butterfly", "fly", "--controller", "simple_rule", "--duration", "-1"],
        ["butterfly", "fly", "--controller", "simple_rule", "--wind", "1"],
        ["butterfly", "fly", "--controller", "simple_rule", "--wind", "a,b"],
        ["butterfly", "fly", "--controller", "simple_rule", "--backend", "nope"],
        ["butterfly", "fly", "--controller", "simple_rule", "--dt", "0"],
        ["butterfly", "speed-limit", "--body-area-cm2", "-1"],
        ["butterfly", "compare", "--controller", "simple_rule", "--config", "nope"],
        ["butterfly", "fly", "--controller", "simple_rule", "--phi-deg", "3"],
        ["butterfly", "nosuchcommand"],
        ["render", "butterfly", "--out", "video.avi"],
    ],
)
def test_bad_input_one_sentence_exit_2(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 2
    lines = [line for line in err.strip().splitlines() if line]
    assert len(lines) == 1 and lines[0].startswith("lifelike-mj: error:")
    assert "Traceback" not in err


def test_malformed_controller_files(capsys, tmp_path):
    cases = {
        "notjson.json": "{not json",
        "list.json": "[1, 2]",
        "noformat.json": json.dumps({"type": "simple_rule"}),
        "badtype.json": json.dumps({"format": "lifelike-mj/butterfly-controller", "type": "warp",
                                    "flap": {"theta_min_deg": -90, "theta_max_deg": 90}, "parameters": {}}),
        "missing.json": json.dumps({"format": "lifelike-mj/butterfly-controller", "type": "simple_rule",
                                    "flap": {"theta_min_deg": -90, "theta_max_deg": 90}, "parameters": {"phi_up_deg": 1}}),
        "badflap.json": json.dumps({"format": "lifelike-mj/butterfly-controller", "type": "constant",
                                    "flap": {"theta_min_deg": 90, "theta_max_deg": -90}, "parameters": {"phi_deg": 0}}),
        "strparam.json": json.dumps({"format": "lifelike-mj/butterfly-controller", "type": "constant",
                                     "flap": {"theta_min_deg": 0, "theta_max_deg": 0}, "parameters": {"phi_deg": "x"}}),
    }
    for name, text in cases.items():
        path = tmp_path / name
        path.write_text(text)
        code, _, err = run(capsys, "butterfly", "fly", "--controller", str(path), "--duration", "1")
        assert code == 2, name
        assert len(err.strip().splitlines()) == 1, name


def test_console_script_exit_code_without_traceback():
    proc = subprocess.run([sys.executable, "-m", "lifelike_mj.cli", "butterfly", "fly", "--controller", "nope"],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


def _options(parser, path=()):
    import argparse

    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            for name, sub in a.choices.items():
                yield from _options(sub, (*path, name))
        elif a.option_strings and a.dest != "help":
            yield " ".join(path), a


def test_every_option_has_help_and_shows_its_default():
    from lifelike_mj.cli import build_parser

    opts = list(_options(build_parser()))
    assert len(opts) > 150
    for where, a in opts:
        assert a.help, f"{where} {a.option_strings[0]} has no help"
    text = build_parser()._subparsers._group_actions[0].choices["fish"]._subparsers._group_actions[0] \
        .choices["swim"].format_help()
    assert "--n FISH, --fish FISH" in text and "(default: 30)" in text


def test_no_help_says_its_default_twice_or_as_a_raw_float():
    """Every option's help, as printed: "(default" at most once, no float with more than 6 significant digits
    (1/1200 s is shown as "1/1200", not 0.0008333333333333334)."""
    import re

    from lifelike_mj.cli import build_parser
    from lifelike_mj.cli.common import HelpFormatter, show_default

    bad = []
    for where, a in _options(build_parser()):
        shown = " ".join(HelpFormatter("x")._expand_help(a).split())
        if len(re.findall(r"\(default", shown, re.I)) > 1 or re.search(r"\d\.\d{7,}|\d{7,}e-", shown):
            bad.append(f"{where} {a.option_strings[0]}: {shown}")
    assert not bad, "\n".join(bad)
    assert show_default(1.0 / 1200) == "1/1200" and show_default(0.1) == "0.1" and show_default([]) == "none"
    assert show_default(2.0 / 3.0) == "0.666667" and show_default((1.5, 0.0)) == "1.5, 0"


def test_negative_values_are_values(capsys):
    code, out, _ = run(capsys, "butterfly", "fly", "--controller", "simple_rule", "--duration", "1", "--wind", "-2,0",
                       "--y0", "-1", "--json")
    assert code == 0 and json.loads(out)["start_altitude_m"] == -1.0


def test_json_output_is_strict_with_undefined_values_named(capsys):
    """One fish for half a second has no burst: its burst measures are undefined, printed as null and named."""
    code, out, _ = run(capsys, "fish", "swim", "--n", "1", "--duration", "0.5", "--json")
    assert code == 0

    def no_constant(name):
        raise AssertionError(f"bare {name} in JSON output")

    d = json.loads(out, parse_constant=no_constant)
    assert d["burst_interval_mean_s"] is None
    assert d["undefined"]["burst_interval_mean_s"] == "not defined for this run (NaN)"


def test_every_command_takes_quiet_and_ends_with_one_done_line(capsys, tmp_path):
    """Every command that runs has ``--quiet``; a run ends with one "done in" line on stderr (its bars, all drawn
    by lifelike_mj.progress, come before it), and ``--quiet`` leaves stderr empty."""
    from lifelike_mj.cli import build_parser
    from lifelike_mj.progress import set_enabled

    def leaves(parser, path=()):
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs:
            yield " ".join(path), parser
        for a in subs:
            for name, child in a.choices.items():
                yield from leaves(child, (*path, name))

    missing = [w for w, p in leaves(build_parser()) if "--quiet" not in p._option_string_actions]
    assert not missing, missing
    try:
        for command in (["fish", "swim", "--n", "2", "--duration", "1"], ["boids", "run", "--n", "20", "--steps", "20"]):
            assert main([*command, "--json"]) == 0
            err = capsys.readouterr().err.strip().splitlines()
            assert err[-1].startswith(f"lifelike-mj {command[0]} {command[1]}: done in ")
            assert sum("done in" in line for line in err) == 1
            assert main([*command, "--json", "--quiet"]) == 0
            assert capsys.readouterr().err == ""
    finally:
        set_enabled(True)


def test_wind_is_given_by_its_meaning_and_the_old_spelling_keeps_its_own_one_release(capsys):
    """--wind-from (where it comes from) and --wind-to (the air's velocity) on the planar and the 3D flight: the
    same wind either way; --wind keeps each command's old meaning (from in 2D, to in 3D) with a note that comes
    after the run (so an error stays one sentence); two spellings at once are refused."""
    from lifelike_mj.cli import build_parser
    from lifelike_mj.cli.common import take_notes

    p = build_parser()
    fly = ["butterfly", "fly", "--controller", "simple_rule"]
    assert p.parse_args([*fly, "--wind-from", "2,0.5"]).wind == (2.0, 0.5)
    assert p.parse_args([*fly, "--wind-to=-2,-0.5"]).wind == (2.0, 0.5)
    assert p.parse_args([*fly, "--wind", "2,0.5"]).wind == (2.0, 0.5)
    assert take_notes() == ["--wind is now --wind-from (where it comes from); --wind goes in the next release."]
    fly3d = ["butterfly", "fly3d"]
    assert p.parse_args([*fly3d, "--wind-to", "1,0,0"]).wind == (1.0, 0.0, 0.0)
    assert p.parse_args([*fly3d, "--wind-from=-1,0,0"]).wind == (1.0, 0.0, 0.0)
    assert p.parse_args([*fly3d, "--wind", "1,0,0"]).wind == (1.0, 0.0, 0.0)
    assert take_notes() == ["--wind is now --wind-to (where it blows to); --wind goes in the next release."]
    runs = []
    for spelling in (["--wind-from", "2,0"], ["--wind-to", "-2,0"], ["--wind", "2,0"]):
        assert main([*fly, "--duration", "1", *spelling, "--json", "--quiet"]) == 0
        out, err = capsys.readouterr()
        runs.append(json.loads(out)["final_altitude_m"])
        assert err == ("" if spelling[0] != "--wind" else
                       "note: --wind is now --wind-from (where it comes from); --wind goes in the next release.\n")
    assert runs[0] == runs[1] == runs[2]
    assert main([*fly, "--wind-from", "2,0", "--wind-to", "1,0"]) == 2
    assert "not allowed with" in capsys.readouterr().err


def test_inputs_say_air_on_both_flights_and_relative_still_works_one_release():
    from lifelike_mj.cli import build_parser
    from lifelike_mj.cli.common import take_notes

    p = build_parser()
    fly = ["butterfly", "fly", "--controller", "ann_paper"]
    assert p.parse_args([*fly, "--inputs", "air"]).inputs == "relative"  # the planar model's own word
    assert p.parse_args([*fly, "--inputs", "ground"]).inputs == "ground" and take_notes() == []
    assert p.parse_args([*fly, "--inputs", "relative"]).inputs == "relative"
    assert take_notes() == ["--inputs relative is now --inputs air (velocities through the air); 'relative' goes "
                            "in the next release."]
    assert p.parse_args(["butterfly", "evolve", "--optimizer", "rcga", "--inputs", "both"]).inputs == "both"
    assert p.parse_args(["butterfly", "evolve3d", "--inputs", "air"]).inputs == "air"
