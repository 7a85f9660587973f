"""evolve3d on the planar evolution's executors: the same seed gives the same controller serially, on a process pool
and on a local Ray cluster, bit for bit."""

import json

import numpy as np

from lifelike_mj.butterfly import flight3d


def _evolve(tmp_path, executor: str, **kw) -> tuple[dict, list]:
    out = tmp_path / f"{executor}.json"
    res, ctl = flight3d.evolve(flight3d.TASK_SETS["wind"]()[:3], out, population=6, generations=2, duration_s=0.3,
                               seed=7, progress=False, executor=executor, **kw)
    data = json.loads(out.read_text())
    assert data["provenance"]["executor"] == executor
    return data, [h["best"] for h in res.history]


def test_same_seed_same_controller_serially_on_a_pool_and_on_ray(tmp_path, local_ray):
    serial, hist = _evolve(tmp_path, "serial")
    for executor in ("process", "ray"):
        other, other_hist = _evolve(tmp_path, executor, workers=2)
        assert np.asarray(other["weights"]).tobytes() == np.asarray(serial["weights"]).tobytes()
        assert other_hist == hist and other["provenance"]["best_fitness"] == serial["provenance"]["best_fitness"]


def test_the_cli_takes_the_executor_options(tmp_path):
    from lifelike_mj.cli import main

    assert main(["butterfly", "evolve3d", "--executor", "serial", "--workers", "2", "--out",
                 str(tmp_path / "x.json")]) == 2
    assert main(["butterfly", "evolve3d", "--ray-address", "127.0.0.1:1", "--out", str(tmp_path / "x.json")]) == 2
    assert not (tmp_path / "x.json").exists()


def test_a_different_seed_is_a_different_controller(tmp_path):
    """(So that the equality above is not that of a run that ignores its seed.)"""
    runs = [flight3d.evolve(flight3d.TASK_SETS["steer"]()[:1], tmp_path / f"{s}.json", population=6, generations=1,
                            duration_s=0.2, seed=s, progress=False)[0] for s in (7, 107)]
    assert runs[0].best_x.tobytes() != runs[1].best_x.tobytes()
