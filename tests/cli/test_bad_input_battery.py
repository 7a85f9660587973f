"""A battery of bad inputs, written as a user would try them: each ends in exit status 2 with one
sentence on stderr (no traceback), within seconds, before anything is written.

Each case: (argv, a piece of the expected sentence, files to create first in the working folder).
"""

import json
import pickle

import pytest
from battery import check_refusal

CTRL = {"format": "lifelike-mj/butterfly-controller", "version": 1, "type": "simple_rule",
        "flap": {"frequency_hz": 10.0, "theta_min_deg": -30.0, "theta_max_deg": 60.0},
        "parameters": {"phi_up_deg": 14.0, "phi_down_deg": 0.0}}
FISH = {"format": "lifelike-mj/fish-preset", "version": 1, "name": "mine", "parameters": {"P_a": 4.0}}
BOIDS = {"format": "lifelike-mj/boids-preset", "version": 1, "name": "mine", "W_a": [[0.5, 0.1], [0.1, 0.5]],
         "W_c": [[0.01, 0.0], [0.0, 0.01]]}
GRID = {"format": "lifelike-mj/boids-grid", "version": 1, "w_a": [0.5, 1.0], "w_c": [0.01]}


def _with(base, **changes):
    d = json.loads(json.dumps(base))
    for k, v in changes.items():
        if k.startswith("p_"):
            d["parameters"][k[2:]] = v
        elif v is None:
            d.pop(k, None)
        else:
            d[k] = v
    return d


def _typo(base, old, new):
    d = json.loads(json.dumps(base))
    d["parameters"][new] = d["parameters"].pop(old)
    return d


FLY = ["butterfly", "fly", "--controller", "simple_rule", "--duration", "1"]
EVO = ["butterfly", "evolve", "--optimizer", "rcga", "--generations", "1", "--executor", "serial"]
SWIM = ["fish", "swim", "--duration", "1"]
RUN = ["boids", "run", "--steps", "20", "--n", "10"]
SWEEP = ["boids", "sweep", "--steps", "20", "--n", "10", "--executor", "serial"]

CASES = [
    # --- butterfly fly: numbers, names, paths
    (["butterfly", "fly"], "--controller", {}),
    (["butterfly", "fly", "--controller", "nosuch"], "unknown controller 'nosuch'", {}),
    (["butterfly", "fly", "--controller", "missing.json"], "does not exist", {}),
    (["butterfly", "fly", "--controller", "adir"], "is a folder", {"adir/": None}),
    (FLY[:4] + ["--duration", "0"], "--duration", {}),
    (FLY[:4] + ["--duration", "-5"], "--duration", {}),
    (FLY[:4] + ["--duration", "nan"], "--duration", {}),
    (FLY[:4] + ["--duration", "1e12"], "(0, 3600] s", {}),
    (FLY[:4] + ["--duration", "abc"], "expected a number", {}),
    (FLY + ["--dt", "0"], "--dt", {}),
    (FLY + ["--dt", "0.05"], "--dt", {}),
    (FLY + ["--dt", "0.02"], "--dt", {}),
    (FLY + ["--y0", "nan"], "--y0", {}),
    (FLY + ["--y0", "1e9"], "[-1000, 1000] m", {}),
    (FLY + ["--wind", "1"], "two numbers", {}),
    (FLY + ["--wind", "a,b"], "two numbers", {}),
    (FLY + ["--wind", "1,2,3"], "two numbers", {}),
    (FLY + ["--wind", "100,0"], "wind component a", {}),
    (FLY + ["--wind", "nan,0"], "finite", {}),
    (FLY + ["--wind", "-2,nan"], "finite", {}),
    (FLY + ["--backend", "gpu"], "\'gpu\' is not one of", {}),
    (FLY + ["--config", "rich"], "only apply to --backend mujoco", {}),
    (FLY + ["--force-mode", "strip"], "only apply to --backend mujoco", {}),
    (FLY + ["--backend", "mujoco", "--config", "huge"], "\'huge\' is not one of", {}),
    (FLY + ["--mass-g", "0"], "--mass-g", {}),
    (FLY + ["--mass-g", "-1"], "--mass-g", {}),
    (FLY + ["--mass-g", "0.00001", "--backend", "mujoco"], "not more than its two wings", {}),
    (FLY + ["--rho", "inf"], "--rho", {}),
    (FLY + ["--cd", "1e6"], "(0, 10]", {}),
    (FLY + ["--phi-up-deg", "1000"], "[-90, 90] deg", {}),
    (FLY + ["--inputs", "sky"], "expected air or ground", {}),
    (FLY + ["--out", "afile"], "is a file; give a folder", {"afile": "x"}),
    (FLY + ["--out", "done"], "already holds summary.json", {"done/summary.json": "{}"}),
    (FLY + ["--out", "/proc/lifelike"], "cannot be written", {}),
    (["butterfly", "fly", "--controller", "c.json"], "is not a JSON file (expecting property name", {"c.json": "{not json"}),
    (["butterfly", "fly", "--controller", "c.json"], "did you mean 'phi_down_deg'",
     {"c.json": _typo(CTRL, "phi_down_deg", "phi_dwn_deg")}),
    (["butterfly", "fly", "--controller", "c.json"], "unknown key 'colour'", {"c.json": _with(CTRL, colour="red")}),
    (["butterfly", "fly", "--controller", "c.json"], "format version 2", {"c.json": _with(CTRL, version=2)}),
    (["butterfly", "fly", "--controller", "c.json"], "is not a butterfly controller", {"c.json": _with(CTRL, format="x")}),
    (["butterfly", "fly", "--controller", "c.json"], "unknown controller type", {"c.json": _with(CTRL, type="magic")}),
    (["butterfly", "fly", "--controller", "c.json"], "phi_up_deg must be a number in [-90, 90], got '14'",
     {"c.json": _with(CTRL, p_phi_up_deg="14")}),
    (["butterfly", "fly", "--controller", "c.json"], "not an object", {"c.json": [1, 2, 3]}),
    (["butterfly", "fly", "--controller", "c.json"], "lacks 'flap'", {"c.json": _with(CTRL, flap=None)}),
    (["butterfly", "fly", "--controller", "c.json"], "did you mean 'theta_min_deg'",
     {"c.json": _with(CTRL, flap={"theta_mn_deg": -30, "theta_max_deg": 60})}),
    # --- butterfly evolve
    (EVO[:2] + ["--optimizer", "nonsense"], "\'nonsense\' is not one of", {}),
    (EVO + ["--population", "0"], "--population", {}),
    (EVO + ["--population", "1e12"], "from 1 to 100,000", {}),
    (EVO[:4] + ["--generations", "0", "--executor", "serial"], "--generations", {}),
    (EVO[:4] + ["--generations", "1.5", "--executor", "serial"], "whole number", {}),
    (EVO + ["--evaluations", "10"], "not both", {}),
    (EVO + ["--seed", "-1"], "--seed", {}),
    (EVO[:6] + ["--workers", "0"], "--workers", {}),
    (EVO + ["--workers", "2"], "does not apply to --executor serial", {}),
    (EVO + ["--ray-address", "10.0.0.1:6379"], "only applies to --executor ray", {}),
    (EVO[:6] + ["--executor", "ray", "--ray-address", "not an address"], "HOST:PORT", {}),
    (EVO + ["--out", "x.txt"], "must end in .json", {}),
    (EVO + ["--out", "a.json", "--checkpoint", "a.json"], "same file", {}),
    (EVO + ["--out", "a.json", "--checkpoint", "notes.txt"], "not a checkpoint", {"notes.txt": "my notes"}),
    (EVO + ["--out", "a.json"], "already exists", {"a.json": "{}"}),
    (EVO + ["--out", "a.json", "--resume"], "old pickled checkpoint",
     {"a.json.ckpt": pickle.dumps({"format": "lifelike_mj.evolve.checkpoint", "version": 1})}),
    (EVO + ["--hidden", "a,b"], "--hidden", {}),
    (EVO + ["--hidden", "0"], "hidden layers", {}),
    (EVO + ["--task", "elsewhere"], "unknown task", {}),
    (EVO + ["--inputs", "sideways"], "expected air, ground or both", {}),
    (EVO + ["--backend", "gpu"], "--backend 'gpu' is not one of paper, mujoco", {}),
    # --- other butterfly commands
    (["butterfly", "windmap", "--controller", "simple_rule"], "network", {}),
    (["butterfly", "windmap", "--controller", "ann_paper", "--step", "1e-9"], "--step", {}),
    (["butterfly", "windmap", "--controller", "ann_paper", "--step", "0.01", "--max", "10"], "wind cells", {}),
    (["butterfly", "windmap", "--controller", "ann_paper", "--plot", "map.jpg"], "must end in .png", {}),
    (["butterfly", "windmap", "--controller", "ann_paper", "--max", "0"], "--max", {}),
    (["butterfly", "windmap", "--controller", "ann_paper", "--plot", "m.png"], "already exists", {"m.png": "x"}),
    (["butterfly", "trim", "--dt", "1"], "--dt", {}),
    (["butterfly", "compare", "--controller", "simple_rule", "--config", "nope"], "is not one of", {}),
    (["butterfly", "speed-limit", "--body-area-cm2", "0"], "--body-area-cm2", {}),
    (["butterfly", "forces", "--span-cm", "nan"], "--span-cm", {}),
    (["butterfly", "assess", "--controller", "glide"], "network", {}),
    # --- the 3D butterfly
    (["butterfly", "fly3d", "--controller", "nosuch"], "unknown 3D controller 'nosuch'", {}),
    (["butterfly", "fly3d", "--controller", "c.json"], "is not a 3D controller", {"c.json": CTRL}),
    (["butterfly", "fly3d", "--speed", "0"], "--speed", {}),
    (["butterfly", "fly3d", "--wind", "1,2"], "three numbers", {}),
    (["butterfly", "fly3d", "--wind", "1,nan,0"], "three numbers", {}),
    (["butterfly", "fly3d", "--task", "loop"], "is not one of", {}),
    (["butterfly", "fly3d", "--predictive"], "--predictive flies a designed controller", {}),
    (["butterfly", "fly3d", "--predictive", "--task", "course", "--controller", "monarch"],
     "--predictive flies a designed controller", {}),
    (["butterfly", "fly3d", "--out", "o"], "already holds", {"o/summary.json": "x"}),
    (["butterfly", "evolve3d", "--tasks", "dance"], "is not one of", {}),
    (["butterfly", "evolve3d", "--inputs", "sky"], "is not one of", {}),
    (["butterfly", "fly3d", "--vertical-gusts", "-1"], "--vertical-gusts", {}),
    (["butterfly", "assess3d", "--wind", "1,0"], "three numbers", {}),
    (["butterfly", "evolve3d", "--hidden", "0,x"], "--hidden", {}),
    (["butterfly", "evolve3d", "--start", "monarch", "--hidden", "8"], "--hidden does not apply", {}),
    (["butterfly", "evolve3d", "--mode", "land"], "give the controller with --start", {}),
    (["butterfly", "evolve3d", "--mode", "hover", "--start", "monarch"], "is not one of", {}),
    (["butterfly", "evolve3d", "--reach", "0.5"], "--reach applies", {}),
    (["butterfly", "evolve3d", "--mode", "land", "--start", "monarch", "--reach", "0"], "--reach", {}),
    (["butterfly", "evolve3d", "--out", "c.json"], "already exists", {"c.json": "{}"}),
    (["butterfly", "evolve3d", "--population", "1"], "--population", {}),
    (["butterfly", "garden", "--n", "0"], "--n", {}),
    (["butterfly", "garden", "--out", "g.avi"], ".mp4", {}),
    (["butterfly", "garden", "--flutter", "2"], "--flutter", {}),
    (["butterfly", "garden", "--paths", "p.png"], "already exists", {"p.png": "x"}),
    (["butterfly", "assess3d", "--courses", "x"], "--courses", {}),
    (["butterfly", "evolve3d", "--animal", "moth"], "is not one of", {}),
    (["butterfly", "measure3d", "--window", "0"], "--window", {}),
    (["butterfly", "measure3d", "--settle", "1", "--window", "0.2"], "needs a duration of at least 1.5 s", {}),
    (["butterfly", "measure3d", "--controller", "nope"], "nope", {}),
    (["butterfly", "strobe3d", "--out", "s.png", "--views", "side,back"], "--views", {}),
    (["butterfly", "strobe3d", "--out", "s.gif"], ".png", {}),
    (["butterfly", "strobe3d", "--out", "s.png"], "already exists", {"s.png": "x"}),
    (["butterfly", "strobe3d", "--out", "s.png", "--n", "1"], "--n", {}),
    (["butterfly", "land3d", "--flowers", "1"], "--flowers", {}),
    (["butterfly", "land3d", "--perch", "-1"], "--perch", {}),
    (["butterfly", "land3d", "--picture", "l.jpg"], ".png", {}),
    (["butterfly", "land3d", "--picture", "l.png"], "already exists", {"l.png": "x"}),
    (["butterfly", "land3d", "--controller", "nosuch"], "nosuch", {}),
    (["butterfly", "evolve3d", "--force-law", "tip"], "is not one of", {}),
    # --- fish
    (SWIM + ["--fish", "0"], "--fish", {}),
    (SWIM + ["--fish", "10000000"], "from 1 to 5,000", {}),
    (SWIM + ["--fish", "2.5"], "whole number", {}),
    (SWIM[:2] + ["--duration", "0"], "--duration", {}),
    (SWIM[:2] + ["--duration", "1e12"], "--duration", {}),
    (SWIM + ["--tank-scale", "0.1"], "[0.35, 10]", {}),
    (SWIM + ["--tank-scale", "100"], "--tank-scale", {}),
    (SWIM + ["--tank", "3,x,1"], "three lengths", {}),
    (SWIM + ["--tank", "3,3"], "three positive lengths", {}),
    (SWIM + ["--tank", "3,3,0.1"], "2.5 body lengths", {}),
    (SWIM + ["--tank", "3,3,nan"], "three positive lengths", {}),
    (SWIM + ["--tank", "3,3,1", "--tank-scale", "2"], "not both", {}),
    (SWIM + ["--tank", "1e6,1,1"], "at most 100 m", {}),
    (SWIM + ["--seed", "-3"], "--seed", {}),
    (SWIM + ["--preset", "nosuch"], "unknown fish preset", {}),
    (SWIM + ["--preset", "p.json"], "must have 3 numbers", {"p.json": _with(FISH, p_brake_dS_v_m2=[1, 2])}),
    (SWIM + ["--preset", "p.json"], "P_a must be a number in [0, 1e+06]", {"p.json": _with(FISH, p_P_a=[1, 2, 3])}),
    (SWIM + ["--preset", "p.json"], "control_hz", {"p.json": _with(FISH, p_control_hz=1e-9)}),
    (SWIM + ["--preset", "p.json"], "format version 2", {"p.json": _with(FISH, version=2)}),
    (SWIM + ["--preset", "p.json"], "unknown key 'P_z'", {"p.json": _with(FISH, p_P_z=1.0)}),
    (SWIM + ["--preset", "p.json"], "did you mean 'r_max_N'", {"p.json": _with(FISH, p_r_max_n=0.03)}),
    (SWIM + ["--preset", "p.json"], "r_min_N", {"p.json": _with(FISH, p_r_min_N=0.05, p_r_max_N=0.01)}),
    (SWIM + ["--preset", "p.json"], "parameters must be an object", {"p.json": _with(FISH, parameters=[1])}),
    (SWIM + ["--preset", "p.json"], "did you mean 'parameters'", {"p.json": {**_with(FISH, parameters=None),
                                                                          "paramters": {}}}),
    (SWIM + ["--preset", "p.json"], "unknown fish preset 'nope'", {"p.json": {"format": "lifelike-mj/fish-preset",
                                                                           "version": 1, "same_as": "nope"}}),
    (SWIM + ["--preset", "p.json"], "substeps", {"p.json": _with(FISH, p_substeps=0.5)}),
    (SWIM + ["--video", "v.avi"], "must end in .mp4 or .gif", {}),
    (SWIM + ["--camera", "top"], "\'top\' is not one of", {}),
    (SWIM + ["--video-duration", "5"], "only applies with --video", {}),
    (SWIM + ["--out", "afile"], "is a file", {"afile": "x"}),
    (SWIM + ["--out", "o"], "already holds measures.json", {"o/measures.json": "{}"}),
    # --- boids
    (RUN + ["--preset", "9z"], "unknown boids preset", {}),
    (RUN[:4] + ["--n", "1"], "--n", {}),
    (RUN[:4] + ["--n", "1e12"], "--n", {}),
    (RUN[:2] + ["--steps", "5"], "--steps", {}),
    (RUN[:2] + ["--steps", "1e12"], "--steps", {}),
    (["boids", "run", "--n", "1000000", "--steps", "1000000"], "agent-steps", {}),
    (RUN + ["--dims", "4"], "--dims '4' is not one of 3, 2", {}),
    (RUN + ["--wa", "0.5,0.1;0.1,0.5"], "both --wa and --wc", {}),
    (RUN + ["--wa", "0.5,0.1;0.1", "--wc", "0.01,0;0,0.01"], "--wa", {}),
    (RUN + ["--preset", "b.json"], "settings must be an object", {"b.json": _with(BOIDS, settings=[1, 2])}),
    (RUN + ["--preset", "b.json"], "box", {"b.json": _with(BOIDS, settings={"box": 1e9})}),
    (RUN + ["--preset", "b.json"], "unknown key 'r_s'", {"b.json": _with(BOIDS, r_s=5)}),
    (RUN + ["--preset", "b.json"], "did you mean 'r_s'", {"b.json": _with(BOIDS, settings={"r_ss": 1.0})}),
    (RUN + ["--preset", "b.json"], "lacks 'W_c'", {"b.json": _with(BOIDS, W_c=None)}),
    (RUN + ["--preset", "b.json"], "format version 3", {"b.json": _with(BOIDS, version=3)}),
    (RUN + ["--plot", "p.txt"], "must end in .png", {}),
    (SWEEP + ["--grid", "g.json"], "lacks 'w_a'", {"g.json": _with(GRID, w_a=None)}),
    (SWEEP + ["--grid", "g.json"], "w_a[0] must be a number in [0, 100]", {"g.json": _with(GRID, w_a=["abc"])}),
    (SWEEP + ["--grid", "g.json"], "w_a must be a list", {"g.json": _with(GRID, w_a="abc")}),
    (SWEEP + ["--x", "wq=0:1:3"], "unknown sweep axis", {}),
    (SWEEP + ["--x", "wa_cross=0:1"], "name=start:stop:count", {}),
    (SWEEP + ["--seeds", "a-b", "--x", "wa_cross=0:1:2"], "--seeds", {}),
    (SWEEP + ["--workers", "2", "--x", "wa_cross=0:1:2"], "does not apply", {}),
    (SWEEP, "--grid", {}),
    # --- the shared verbs
    (["render", "butterfly", "--out", "v.avi"], "must end in .mp4 or .gif", {}),
    (["render", "butterfly", "--out", "v.mp4", "--camera", "bogus"], "\'bogus\' is not one of", {}),
    (["render", "fish", "--out", "v.mp4", "--fps", "0"], "--fps", {}),
    (["render", "fish", "--out", "v.mp4", "--width", "100000"], "--width", {}),
    (["render", "boids", "--out", "v.mp4", "--duration", "5"], "has no option", {}),
    (["render", "butterfly", "--out", "v.mp4"], "already exists", {"v.mp4": "x"}),
    (["render", "butterfly", "--out", "v.mp4", "--duration", "1e9"], "--duration", {}),
    (["view", "boids", "--duration", "5"], "has no option", {}),
    (["view", "fish", "--duration", "-1"], "--duration", {}),
    (["bench", "butterfly", "--repeats", "0"], "--repeats", {}),
    (["bench", "butterfly", "--out", "b.txt"], "must end in .json", {}),
    (["reproduce", "butterfly", "--out", "afile"], "is a file", {"afile": "x"}),
    (["reproduce", "all", "--out", "r"], "already holds report.md", {"r/fish/report.md": "mine"}),
    (["export", "butterfly3d", "--out", "run.obj"], "must end in .glb or .gltf", {}),
    (["export", "fish", "--out", "run.glb", "--format", "usd"], "format usd is written to a file ending in .usda", {}),
    (["export", "boids", "--out", "run.glb"], "already exists", {"run.glb": "mine"}),
    (["export", "boids", "--out", "run.glb", "--steps", "3", "--steps-per-frame", "5"], "fewer than one frame", {}),
    (["export", "boids", "--out", "run.glb", "--duration", "5"], "has no option", {}),
    (["export", "fish", "--out", "run.html", "--fps", "0"], "--fps", {}),
    (["export", "fish", "--out", "run.html", "--start", "-1"], "--start", {}),
    (["export", "butterfly", "--out", "run.usda", "--duration", "1e9"], "--duration", {}),
    (["export", "butterfly3d", "--out", "run.glb", "--controller", "nosuch"], "nosuch", {}),
    (["export", "butterfly3d", "--out", "run.glb", "--garden", "501"], "--garden", {}),
    (["export", "butterfly3d", "--out", "adir/run.glb"], "", {"adir": "a file, not a folder"}),
    (["export", "fish", "--out", "run.glb", "--rotations", "half"], "\'half\' is not one of", {}),
    (["nonsense"], "has no command 'nonsense'", {}),
    (["butterfly"], "required", {}),
    (["fish", "swim", "--fihs", "3"], "has no option", {}),
]


def test_the_battery_is_large():
    assert len(CASES) >= 100


@pytest.mark.parametrize("argv, needle, files", CASES, ids=[" ".join(c[0])[:60] for c in CASES])
def test_bad_input_is_one_sentence_and_exit_2(argv, needle, files, tmp_path, monkeypatch, capsys):
    check_refusal(argv, needle, files, tmp_path, monkeypatch, capsys)
