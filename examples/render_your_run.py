"""Render runs you made yourself: a butterfly trajectory as a GIF, a boids run as a PNG frame,
and a fish swim as a GIF. No display needed (offscreen EGL or OSMesa).

    python examples/render_your_run.py [OUT_DIR]
"""

import argparse
from pathlib import Path

from lifelike_mj import boids, butterfly, fish


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out_dir", nargs="?", default="out/examples", help="the folder to write into (default out/examples)")
    out = Path(ap.parse_args().out_dir)
    out.mkdir(parents=True, exist_ok=True)

    trajectory = butterfly.Flight("simple_rule").record(duration_s=1.0)  # the paper backend
    info = butterfly.film_flight(out / "flight.gif", butterfly.playback(trajectory), duration_s=1.0, fps=20,
                                 width=240, height=180, slowdown=2.0)
    print(f"butterfly: {info['frames']} frames -> {info['path']}")

    run = boids.simulate(boids.load_preset("4c"), n=300, n_steps=1500, seed=0, record_every=500)
    last = boids.playback(run)
    last.step(len(run.steps) - 1)
    boids.render.frame_png(out / "flock.png", last, width=320, height=240)
    print(f"boids: step {run.steps[-1]} -> {out / 'flock.png'}")

    swim = fish.Tank(fish.load_preset("B-D"), n_fish=5, seed=0, size=(1.5, 0.4, 0.6)).record(duration_s=2.0)
    info = fish.film_tank(out / "tank.gif", fish.playback(swim), duration_s=2.0, fps=15, width=240, height=180)
    print(f"fish: {info['frames']} frames -> {info['path']}")


if __name__ == "__main__":
    main()
