"""The fish of Satoi, Nakadai, Hoshino 2015 on MuJoCo: model, drag, motion units, vision, presets,
determinism, the tank's walls, runaway detection and the four-pattern ordering."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import mujoco
import numpy as np
import pytest

from lifelike_mj.cli import main
from lifelike_mj.errors import Diverged, UserError
from lifelike_mj.fish import sim
from lifelike_mj.fish.experiments import drag_check, pattern_table, swim_summary, write_tracks
from lifelike_mj.fish.params import ACCELERATE, PRESETS, FishParams, load_preset
from lifelike_mj.fish.scene import BODY_LENGTH_M, base_spec, build_scene, fish_name, tank_size
from lifelike_mj.physics.callbacks import passive_callback

BD = load_preset("B-D")


# ---- model and scene ---------------------------------------------------------------------------


def test_fish_mass_inertia_and_neutral_water():
    sc = build_scene(3)
    m = sc.model
    assert sc.n == 3 and m.nbody == 4 and m.njnt == 3
    a, b, c = 0.032, 0.005, 0.011  # the solid ellipsoid of models/fish.xml at 1000 kg/m^3
    mass = 4 / 3 * math.pi * a * b * c * 1000.0
    assert sc.mass_kg == pytest.approx(mass, rel=1e-4)
    np.testing.assert_allclose(sc.inertia, [mass / 5 * (b * b + c * c), mass / 5 * (a * a + c * c),
                                            mass / 5 * (a * a + b * b)], rtol=1e-4)
    assert np.all(m.body_gravcomp[sc.body] == 1.0)
    # looks, collision and mass separated: only the collision geom collides, no geom carries mass
    for i in sc.body:
        geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == i]
        colliding = [g for g in geoms if m.geom_contype[g] or m.geom_conaffinity[g]]
        assert [m.geom(g).name.split("/")[-1] for g in colliding] == ["collision"]
    # no net sinking: a still fish stays put for a simulated second
    d = mujoco.MjData(m)
    d.qpos[sc.qadr] = [-1.0, 0.0, 1.0]
    d.qpos[sc.qadr + 2] = 0.5  # mid-water (the model places every fish at the origin, on the floor)
    z0 = d.qpos[sc.qadr + 2].copy()
    for _ in range(480):
        mujoco.mj_step(m, d)
    np.testing.assert_allclose(d.qpos[sc.qadr + 2], z0, atol=1e-12)


def test_tank_scales_with_the_filmed_tank_and_names_fish():
    assert tank_size(1.0) == (5.0, 0.5, 1.0)
    assert tank_size(0.4) == pytest.approx((2.0, 0.2, 0.4))
    sc = build_scene(40, tank_size(0.5))
    m = sc.model
    assert m.body(fish_name(39)).id == sc.body[39]
    assert m.geom("wall_right").size[1] == pytest.approx(0.125)
    assert m.geom("lid").pos[2] == pytest.approx(0.5 + 0.02)
    with pytest.raises(UserError):
        tank_size(-1.0)
    with pytest.raises(UserError):
        build_scene(0)


def test_compiled_callback_equals_python_reference():
    sw = sim.Tank(BD, 4, seed=3)
    m, d = sw.scene.model, sw.data
    rng = np.random.default_rng(0)
    d.qvel[:] = rng.normal(scale=0.3, size=m.nv)
    for i in range(4):
        q = rng.normal(size=4)
        d.qpos[sw.scene.qadr[i] + 3: sw.scene.qadr[i] + 7] = q / np.linalg.norm(q)
        b = sim.U_FISH + sim.FISH_BLOCK * i
        d.userdata[b + 2] = i  # one fish in each MU
        d.userdata[b + 3: b + 6] = rng.normal(scale=0.01, size=3)
    out = {}
    for name, cb in (("compiled", sim.COMPILED_PASSIVE), ("python", sim.python_passive)):
        with passive_callback(cb):
            mujoco.mj_forward(m, d)
        out[name] = d.qfrc_passive.copy()
    assert np.max(np.abs(out["python"])) > 1e-4
    np.testing.assert_allclose(out["compiled"], out["python"], rtol=1e-12, atol=1e-15)


def test_drag_check_matches_mujoco_fluid_model():
    r = drag_check(trials=50)
    assert r["max_rel_error"] < 1e-9


# ---- motion units and control ------------------------------------------------------------------


def test_transition_matrix_rows_are_normalised_weights():
    p = FishParams(P_a=4.0, P_b=0.5, P_c=1.0, P_d=2.0, P_e=1.0)
    T = p.transition_matrix()
    np.testing.assert_allclose(T.sum(axis=1), 1.0)
    np.testing.assert_allclose(T[0], np.array([4, 1, 2, 1]) / 8)
    for i in (1, 2, 3):
        np.testing.assert_allclose(T[i], np.array([0.5, 1, 2, 1]) / 4.5)
    Ta = p.transition_matrix(avoiding=True)
    assert Ta[1, ACCELERATE] > T[1, ACCELERATE] and Ta[0, ACCELERATE] > T[0, ACCELERATE]
    pi = p.stationary()
    np.testing.assert_allclose(pi @ T, pi, atol=1e-12)


def test_mu_log_follows_the_chain():
    """Far from walls (no avoidance), the empirical transition frequencies match the matrix."""
    p = replace(BD, vision_distance_m=1e-3)  # never sees a wall in time: pure free swimming
    r = sim.swim(p, 20, 60.0, seed=1, size=tank_size(3.0))
    mu = r.mu[1:] % 4
    T = p.transition_matrix()
    counts = np.zeros((4, 4))
    for f in range(mu.shape[1]):
        np.add.at(counts, (mu[:-1, f], mu[1:, f]), 1)
    emp = counts / counts.sum(axis=1, keepdims=True)
    n = counts.sum(axis=1, keepdims=True)
    se = np.sqrt(T * (1 - T) / n)
    assert np.all(np.abs(emp - T) < 5 * se + 1e-12)


def test_balance_restores_pitch():
    """The third term of theta (eq. 2-9) must reduce |pitch|: start nose-up 30 deg, no random pitch."""
    p = replace(BD, theta_range_deg=0.0, phi_range_deg=0.0, P_b=1.0, vision_distance_m=1e-3)
    sw = sim.Tank(p, 1, seed=0, size=tank_size(3.0))
    a = sw.scene.qadr[0]
    pitch = math.radians(30.0)
    sw.data.qpos[a + 3: a + 7] = [math.cos(pitch / 2), 0.0, -math.sin(pitch / 2), 0.0]  # nose up
    mujoco.mj_forward(sw.scene.model, sw.data)

    def nose_up_deg():
        w, x, y, z = sw.data.qpos[a + 3: a + 7]
        return math.degrees(math.asin(2 * (x * z - w * y)))

    assert nose_up_deg() == pytest.approx(30.0)
    sw.run(180, record=False)
    assert abs(nose_up_deg()) < 10.0
    p0 = replace(p, balance_A_deg=0.0, buoyancy_offset_m=0.0)
    sw0 = sim.Tank(p0, 1, seed=0, size=tank_size(3.0))
    sw0.data.qpos[a + 3: a + 7] = sw.data.qpos[a + 3: a + 7] * 0 + [math.cos(pitch / 2), 0.0, -math.sin(pitch / 2), 0.0]
    sw0.run(180, record=False)
    w, x, y, z = sw0.data.qpos[a + 3: a + 7]
    assert math.degrees(math.asin(2 * (x * z - w * y))) > 20.0  # without balance it stays pitched


def test_same_seed_same_tracks_in_any_chunking():
    a = sim.swim(BD, 5, 6.0, seed=7)
    b = sim.swim(BD, 5, 6.0, seed=7, chunk_s=0.35)
    c = sim.swim(BD, 5, 6.0, seed=8)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.mu, b.mu)
    assert not np.array_equal(a.positions, c.positions)


def test_vision_sees_an_obstacle_added_to_the_scene():
    """A box added to the base scene is seen by the rays (the fish avoids it), a fish-free tank is not."""
    def run(with_rock: bool):
        spec = base_spec(tank_size(1.0))
        if with_rock:
            spec.worldbody.add_geom(name="rock", type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.05, 0.2, 0.5],
                                    pos=[0.2, 0.0, 0.5], contype=0, conaffinity=1)
        scene = build_scene(1, tank_size(1.0), spec=spec, nuserdata=sim.U_FISH + sim.FISH_BLOCK)
        sw = sim.Tank(replace(BD, theta_range_deg=0.0, phi_range_deg=0.0), 1, seed=0, scene=scene)
        a = scene.qadr[0]
        sw.data.qpos[a: a + 7] = [0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0]  # heading +x towards the rock
        sw.data.qvel[:] = 0.0
        sw.data.qvel[0] = 0.15
        mujoco.mj_forward(scene.model, sw.data)
        _, _, mu = sw.run(30)
        return bool((mu >= 4).any())

    assert run(True) and not run(False)


# ---- tank, runaway, presets ----------------------------------------------------------------------


def test_no_fish_leaves_the_tank_and_no_nan():
    r = sim.swim(BD, 10, 120.0, seed=2, size=tank_size(0.4))  # a small tank: walls met all the time
    assert np.all(np.isfinite(r.positions))
    assert not r.outside_tank().any()
    assert (r.mu >= 4).mean() > 0.2  # the walls were seen often


def test_runaway_speed_is_an_error_naming_the_parameter():
    with pytest.raises(UserError, match="P_a"):
        sim.swim(replace(BD, P_a=1000.0), 5, 60.0, seed=0)
    with pytest.raises(UserError, match="P_b"):
        sim.swim(replace(BD, P_b=1000.0), 5, 60.0, seed=0)


def test_strong_forces_make_mujoco_reset_and_that_is_an_error_naming_them(tmp_path, monkeypatch):
    """r = 10-20 N on a 3 g fish: MuJoCo finds huge accelerations and resets the tank inside mj_step; the
    run must stop with the cause (not swim on from the start), and MuJoCo must not litter the folder."""
    monkeypatch.chdir(tmp_path)
    strong = replace(BD, r_min_N=10.0, r_max_N=20.0)
    with pytest.raises(Diverged, match=r"became unstable.*huge accelerations.*r_min_N = 10 \(default 0.01\)") as info:
        sim.swim(strong, 10, 2.0, seed=0)
    assert info.value.step > 0
    assert not (tmp_path / "MUJOCO_LOG.TXT").exists()
    tank = sim.Tank(BD, 3, seed=0)
    tank.step(5)
    tank.data.qpos[0] = 1e11  # a fish flung a hundred million km away: MuJoCo resets
    with pytest.raises(Diverged, match="huge positions"):
        tank.step(5)


def test_a_runaway_after_raised_forces_names_the_forces():
    with pytest.raises(Diverged, match=r"ran away.*r_max_N = 0.3 \(default 0.03\)"):
        sim.swim(replace(BD, r_max_N=0.3), 5, 60.0, seed=0)


@pytest.mark.parametrize("name", PRESETS)
def test_presets_load_with_units_in_every_name(name):
    p = load_preset(name)
    assert p.name == name
    for k in p.to_dict():
        assert k.startswith("P_") or k in ("cd", "cd_rot", "substeps", "avoid_accel_gain", "avoid_force_scale",
                                           "kick_gamma_shape", "social_neighbours", "social_turn_gain",
                                           "fish_contacts") \
            or any(k.endswith(u) for u in ("_N", "_deg", "_m", "_m2", "_m5", "_s", "_hz", "_kg_m3", "_per_deg",
                                           "_bl_s", "_bl", "_rad", "_rad_per_bl")), k
    assert load_preset("default") == load_preset("B-D")


@pytest.mark.parametrize("bad, match", [
    (dict(P_a=-1.0), "negative"),
    (dict(P_a=0.0, P_b=0.0, P_c=0.0, P_d=0.0, P_e=0.0), "zero"),
    (dict(r_min_N=0.05, r_max_N=0.01), "r_min_N"),
    (dict(cd=float("nan")), "finite"),
])
def test_bad_parameters_are_one_sentence(bad, match):
    with pytest.raises(UserError, match=match):
        replace(BD, **bad)


def test_write_tracks_and_summary(tmp_path):
    r = sim.swim(BD, 3, 2.0, seed=0)
    files = write_tracks(r, tmp_path)
    z = np.load(files["npz"])
    assert z["positions"].shape == (121, 3, 3) and z["mu"].max() <= 3
    lines = files["csv"].read_text().splitlines()
    assert lines[0] == "time_s,fish,x_m,y_m,z_m,mu,avoiding" and len(lines) == 1 + 121 * 3
    s = swim_summary(r)
    json.dumps(s)
    for k in ("burst_interval_mean_s", "burstiness", "accel_kurtosis", "turn_entropy", "mu_entropy_rate",
              "mean_speed_body_lengths_s", "fish_outside_tank"):
        assert k in s


# ---- the paper's observations ----------------------------------------------------------------------


def test_patterns_order_as_the_paper_ratings_for_every_seed():
    """F4: B-D above NB-ND on burstiness and diversity, B above NB on burstiness, D above ND on
    diversity, seed by seed (3 seeds x 40 s here; the report uses 5 x 60 s)."""
    table = pattern_table(seeds=(0, 1, 2), duration_s=40.0, n_fish=10)
    # the orderings the paper's ratings imply (Satoi 2015 Fig. 11-12), written out here, not taken from the code
    expected = {f"{hi} > {lo} on {k}" for k in ("burstiness", "accel_kurtosis")
                for hi, lo in (("B-D", "NB-ND"), ("B-D", "NB-D"), ("B-ND", "NB-ND"))}
    expected |= {f"{hi} > {lo} on turn_entropy" for hi, lo in (("B-D", "NB-ND"), ("B-D", "B-ND"), ("NB-D", "NB-ND"))}
    assert set(table.checks) == expected
    failed = {k: c["margins"] for k, c in table.checks.items() if not c["holds"]}
    assert not failed


def test_calibration_bursts_histogram_and_speed():
    """F1/F3 for B-D: a burst every 0.3-1 s, the acceleration histogram peaks near 0 and leans
    positive, speeds of a 7 cm damselfish (1-4 body lengths/s on average)."""
    r = sim.swim(BD, 10, 30.0, seed=0)
    s = swim_summary(r)
    assert 0.3 <= s["burst_interval_mean_s"] <= 1.0
    assert s["accel_skewness"] > 0
    assert abs(s["accel_mode_bl_s2"]) < 2.0
    assert 1.0 < s["mean_speed_body_lengths_s"] < 4.0
    assert s["max_speed_body_lengths_s"] * BODY_LENGTH_M < 1.0  # m/s


# ---- command line ------------------------------------------------------------------------------------


def test_cli_swim_json(capsys, tmp_path):
    code = main(["fish", "swim", "--fish", "3", "--duration", "3", "--json", "--out", str(tmp_path)])
    out, _ = capsys.readouterr()
    assert code == 0
    d = json.loads(out)
    assert d["fish"] == 3 and d["fish_outside_tank"] == 0
    for name in ("tracks.npz", "tracks.csv", "measures.json", "tracks.png", "accel_histogram.png"):
        assert (tmp_path / name).stat().st_size > 0


def test_cli_drag_check(capsys):
    assert main(["fish", "drag-check", "--json"]) == 0
    assert json.loads(capsys.readouterr()[0])["max_rel_error"] < 1e-9


@pytest.mark.parametrize("argv", [
    ["fish", "swim", "--preset", "nonsense"],
    ["fish", "swim", "--fish", "0"],
    ["fish", "swim", "--duration", "-1"],
    ["fish", "swim", "--tank-scale", "0"],
    ["fish", "swim", "--video", "x.avi"],
    ["fish", "swim", "--video", "x.gif", "--camera", "top"],
])
def test_cli_bad_input_exit_2(capsys, argv):
    assert main(argv) == 2
    err = capsys.readouterr()[1]
    assert err.startswith("lifelike-mj: error:") and err.count("\n") == 1


def test_cli_bad_preset_file_exit_2(capsys, tmp_path):
    bad = tmp_path / "bad.json"
    data = load_preset("B-D").to_file_dict()
    data["parameters"]["P_b"] = -0.1
    bad.write_text(json.dumps(data))
    assert main(["fish", "swim", "--preset", str(bad)]) == 2
    assert "P_b" in capsys.readouterr()[1]
    data["parameters"]["r_min_N"] = 1.0
    data["parameters"]["P_b"] = 0.1
    bad.write_text(json.dumps(data))
    assert main(["fish", "swim", "--preset", str(bad)]) == 2
    assert "r_min_N" in capsys.readouterr()[1]


def test_reproduce_fish_writes_report_results_and_figures(tmp_path):
    from lifelike_mj.fish.report import reproduce_fish

    res = reproduce_fish(tmp_path, seeds=(0, 1), pattern_s=10.0, swim_s=5.0, progress=False)
    text = (tmp_path / "report.md").read_text()
    assert "F4" in text and "B-D > NB-ND on burstiness" in text
    assert json.loads((tmp_path / "results.json").read_text())["drag_check"]["max_rel_error"] < 1e-9
    assert res["swim"]["fish"] == 10
    assert "Living together" in text and "nearest neighbour" in text
    for name in ("fig7_tracks.png", "fig8_accel_histogram.png", "fig11_patterns.png", "group.png", "tracks.csv", "tracks.npz"):
        assert (tmp_path / name).stat().st_size > 0


def _push_by_hand(p: FishParams, u, pitch_deg, mass, inertia):
    """Satoi 2015 eq. 2-9 written again from the paper, independently of the compiled control step: the
    push r ~ U(r_min, r_max) in the direction (theta, phi) (deg) with theta = 90 + U(-range) + the
    balance term A sgn(p) / (1 + exp(-k |p|)) of the pitch p, phi = 90 + U(-range); the forward share
    pushes the body, the lateral and vertical shares turn it with angular acceleration share / (m R^2)."""
    r = p.r_min_N + (p.r_max_N - p.r_min_N) * u[1]
    balance = p.balance_A_deg * np.sign(pitch_deg) / (1.0 + math.exp(-p.balance_k_per_deg * abs(pitch_deg)))
    theta = math.radians(90.0 + p.theta_range_deg * (2 * u[2] - 1) + balance)
    phi = math.radians(90.0 + p.phi_range_deg * (2 * u[3] - 1))
    forward = r * math.sin(theta) * math.sin(phi)
    lateral = r * math.sin(theta) * math.cos(phi)
    vertical = r * math.cos(theta)
    mr2 = mass * p.inertia_radius_m**2
    return forward, -inertia[1] * vertical / mr2, inertia[2] * lateral / mr2  # N; N m about left and up axes


def test_the_compiled_push_equals_the_papers_equations_by_hand():
    """A reference twin of the accelerate MU (section 3.4.1): after one control step with every fish
    accelerating, each fish's push equals the hand computation from the same random draws."""
    import copy

    n = 12
    tank = sim.Tank(BD, n, seed=11, mu_policy=lambda t: np.zeros(n))
    tank.step(30)  # let them tilt: the balance term then matters
    q = tank.data.qpos.copy()
    states = [copy.deepcopy(g.bit_generator.state) for g in tank.rngs]
    tank.step(1)
    ud = tank.data.userdata
    checked = 0
    for i in range(n):
        if tank.state_array[i, sim.S_AVOID_T] > 0:  # a wall in sight: the avoidance turn applies too
            continue
        g = np.random.Generator(np.random.PCG64())
        g.bit_generator.state = states[i]
        u = g.random((1, 4))[0]
        qa = int(tank.scene.qadr[i])
        R = np.empty(9)
        mujoco.mju_quat2Mat(R, q[qa + 3 : qa + 7])
        pitch = math.degrees(math.asin(max(-1.0, min(1.0, R[6]))))
        want = _push_by_hand(BD, u, pitch, tank.scene.mass_kg, tank.scene.inertia)
        base = sim.U_FISH + sim.FISH_BLOCK * i
        np.testing.assert_allclose(ud[base + 3 : base + 6], want, rtol=1e-12, atol=1e-15)
        checked += 1
    assert checked >= 5


def test_the_righting_moment_is_weight_times_the_buoyancy_offset():
    """Buoyancy (ours, not the paper's): the water carries the weight m g at a point buoyancy_offset_m
    above the centre of mass, so a fish tilted by an angle a feels m g h sin(a) righting it."""
    tank = sim.Tank(BD, 2, seed=0)
    g = float(np.linalg.norm(tank.scene.model.opt.gravity))
    assert g == pytest.approx(9.81)
    assert tank.data.userdata[sim.U_RIGHT] == pytest.approx(tank.scene.mass_kg * 9.81 * 0.001, rel=1e-12)
    assert BD.buoyancy_offset_m == 0.001


def test_the_smallest_tank_scale_is_accepted(capsys):
    """--tank-scale's stated lower bound (0.35: every side 2.5 body lengths) is itself accepted."""
    from lifelike_mj.cli.fish import MIN_TANK_SCALE

    assert MIN_TANK_SCALE * min(0.5, 1.0) == pytest.approx(2.5 * BODY_LENGTH_M)
    assert main(["fish", "swim", "--n", "1", "--duration", "0.2", "--tank-scale", str(MIN_TANK_SCALE)]) == 0
    assert main(["fish", "swim", "--n", "1", "--duration", "0.2", "--tank-scale", "0.3499"]) == 2


def test_the_tank_can_be_given_by_its_sides(tmp_path):
    """``--tank L,D,H`` (the open tank of the school presets) reaches the tank and its record."""
    import json

    out = tmp_path / "open"
    assert main(["fish", "swim", "--preset", "school", "--n", "2", "--duration", "0.5", "--tank", "3,3,1",
                 "--out", str(out)]) == 0
    rec = json.loads((out / "measures.json").read_text())
    assert rec["provenance"]["parameters"]["tank_m"] == [3.0, 3.0, 1.0]
    assert rec["provenance"]["parameters"]["preset"]["name"] == "school"
