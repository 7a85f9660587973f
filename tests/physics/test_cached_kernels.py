"""The MuJoCo kernels are cached on disk and give the same numbers when loaded from the cache in a
new process (physics/mjabi.py: MuJoCo's functions linked by name, mjData offsets passed as an
argument, the cfunc trampolines cached per MuJoCo layout)."""

from __future__ import annotations

import os
import subprocess
import sys

CODE = (
    "from lifelike_mj.butterfly import Flight\n"
    "from lifelike_mj.fish import Tank\n"
    "from lifelike_mj.butterfly.backends import mj\n"
    "out = []\n"
    "for cfg in ('paper', 'rich'):\n"
    "    tr = Flight('ann_paper', backend='mujoco', config=cfg).record(n_steps=600)\n"
    "    out.append(tr.y.tobytes().hex()[-32:] + repr(tr.fitness))\n"
    "r = Tank(n_fish=3, seed=2, size=(1.0, 0.3, 0.5)).record(n_steps=30)\n"
    "out.append(r.positions.tobytes().hex()[-32:])\n"
    "from lifelike_mj.butterfly.evolution import make_problem\n"
    "import dataclasses, numpy as np\n"
    "p = dataclasses.replace(make_problem('paper', backend='mujoco'), duration_s=0.1)\n"
    "out.append(repr(p.evaluate(np.full((2, 49), 0.1)).tolist()))\n"
    "from lifelike_mj.fish import sim\n"
    "stats = [f.stats for f in (mj.advance, mj.record_steps, mj._passive_kernel, sim._run_chunk)]\n"
    "misses = sum(sum(s.cache_misses.values()) for s in stats)\n"
    "out.append(f'misses={misses},cfunc_hits={mj._PASSIVE.cache_hits + sim._PASSIVE.cache_hits}')\n"
    "print(' '.join(out))\n"
)


def test_mujoco_kernels_load_from_the_cache_and_compute_the_same(tmp_path):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"))
    runs = [subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, env=env, timeout=600)
            for _ in range(2)]
    for r in runs:
        assert r.returncode == 0, r.stderr[-2000:]
    first, second = (r.stdout.split() for r in runs)
    assert first[:-1] == second[:-1]  # the same numbers, bit for bit
    assert first[-1].startswith("misses=") and first[-1] != "misses=0,cfunc_hits=2"  # compiled the first time
    assert second[-1] == "misses=0,cfunc_hits=2"  # everything loaded from the cache the second time
