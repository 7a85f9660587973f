"""Make the pictures at the top of the README (docs/figures/readme_*.{gif,png}) through the public API.

    python docs/make_pictures.py
"""

from pathlib import Path

from lifelike_mj import boids, butterfly, fish

OUT = Path(__file__).resolve().parent / "figures"


def main() -> None:
    flight = butterfly.Flight("ann_paper", backend="mujoco")
    flight.step(int(round(5.0 / flight.dt)))  # settled flight
    butterfly.film_flight(OUT / "readme_butterfly.gif", flight, duration_s=0.4, fps=25, width=320, height=240,
                          slowdown=5.0)
    tank = fish.Tank(fish.load_preset("B-D"), n_fish=10, seed=0)
    tank.step(300)
    fish.render.frame_png(OUT / "readme_fish.png", tank, camera="follow", width=320, height=240)
    flock = boids.Flock(boids.load_preset("4c"), n=300, seed=0)
    flock.step(3000)
    boids.render.frame_png(OUT / "readme_boids.png", flock, width=320, height=240)
    print("wrote", ", ".join(p.name for p in sorted(OUT.glob("readme_*"))))


if __name__ == "__main__":
    main()
