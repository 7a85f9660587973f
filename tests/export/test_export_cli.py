"""``lifelike-mj export``: each format from the command line, its provenance, and no lost work."""

import json

import pygltflib
import pytest

from lifelike_mj.cli import main


@pytest.mark.parametrize("name", ["tank.glb", "tank.gltf", "tank.usda", "tank.html"])
def test_export_writes_each_format_with_what_made_it(name, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    if name.endswith(".usda"):
        pytest.importorskip("pxr", reason="usd-core is not installed (the usd extra)")
    argv = ["export", "fish", "--n", "3", "--seed", "4", "--start", "0.5", "--duration", "0.5", "--fps", "20",
            "--out", name, "--json"]
    assert main(argv) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["frames"] == 11 and info["bodies"] == 3 and info["bytes"] == (tmp_path / name).stat().st_size
    assert info["span_s"] == pytest.approx(0.5, abs=1 / 60)
    if name.endswith((".glb", ".gltf")):
        prov = pygltflib.GLTF2().load(name).asset.extras
    elif name.endswith(".usda"):
        from pxr import Usd

        stage = Usd.Stage.Open(name)  # held: its layer lives as long as the stage
        prov = json.loads(stage.GetRootLayer().customLayerData["lifelike_mj"])
    else:
        text = (tmp_path / name).read_text()
        prov = json.loads(text.split('<script type="application/json" id="provenance">')[1].split("</script>")[0])
    assert prov["command"].startswith("lifelike-mj export fish") and prov["frames"]["start_s"] == pytest.approx(0.5)
    assert {"creature": "fish", "fish": 3, "seed": 4, "start": 0.5, "fps": 20}.items() <= prov["parameters"].items()
    # the same command again: refused, the file unchanged; with --overwrite: replaced
    before = (tmp_path / name).read_bytes()
    assert main(argv) == 2 and "already exists" in capsys.readouterr().err
    assert (tmp_path / name).read_bytes() == before
    assert main([*argv, "--overwrite"]) == 0


def test_the_same_seed_exports_the_same_motion(tmp_path):
    for k in (1, 2):
        assert main(["export", "boids", "--n", "50", "--steps", "50", "--out", str(tmp_path / f"f{k}.glb")]) == 0
    a, b = (pygltflib.GLTF2().load(str(tmp_path / f"f{k}.glb")).binary_blob() for k in (1, 2))
    assert a == b


def test_a_garden_exports_every_butterfly_and_one_overview(tmp_path, capsys):
    out = tmp_path / "garden.glb"
    assert main(["export", "butterfly3d", "--garden", "3", "--duration", "0.5", "--out", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    gl = pygltflib.GLTF2().load(str(out))
    bodies = [n for n in gl.nodes if n.extras.get("mujoco_body")]
    assert info["bodies"] == len(bodies) and len(bodies) % 3 == 0 and len(bodies) >= 3
    assert [c.name for c in gl.cameras] == ["overview"]  # three butterflies: no single one to follow


def test_usd_without_usd_core_is_one_sentence_before_any_work():
    import subprocess
    import sys

    code = ("import sys; sys.modules['pxr'] = None; from lifelike_mj.cli import main; "
            "sys.exit(main(['export', 'fish', '--out', 'never.usda', '--duration', '600']))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and r.stderr.strip() == ('lifelike-mj: error: USD export needs usd-core: pip install '
                                                      '"lifelike-mj[usd]" (or pip install usd-core).')
