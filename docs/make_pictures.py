"""Make the pictures at the top of the README (docs/figures/readme_*.{gif,png}) and of the environments' pages
(docs/figures/env_*.png) through the public API.

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
    envs()
    print("wrote", ", ".join(p.name for p in sorted([*OUT.glob("readme_*"), *OUT.glob("env_*")])))


def envs() -> None:
    """A frame of each environment's ``rgb_array`` rendering, flown by a shipped controller as a policy."""
    import gymnasium as gym
    import numpy as np

    import lifelike_mj.envs  # noqa: F401  (registers the environments)
    from lifelike_mj.envs.policies import controller_policy
    from lifelike_mj.render.video import write_png

    env = gym.make("lifelike_mj/ButterflyPitch-v0", backend="mujoco", action_mode="phi", render_mode="rgb_array",
                   width=480, height=320)
    policy = controller_policy("ann_paper", env.unwrapped)
    obs, _ = env.reset(seed=0)
    for _ in range(6000):  # 5 s: settled flight
        obs, *_ = env.step(policy(obs))
    write_png(OUT / "env_butterfly_pitch.png", env.render())
    # the shipped default as the baseline, a residual policy of zeros on top: the designed controller's own flight
    env = gym.make("lifelike_mj/ButterflyFlight3D-v0", controller="designed", task="turn", duration_s=10.0,
                   render_mode="rgb_array", width=480, height=320)
    env.reset(seed=0)
    zeros = np.zeros(env.action_space.shape)
    while env.unwrapped.flight.time < 2.6:  # in the turn
        env.step(zeros)
    write_png(OUT / "env_butterfly_flight3d.png", env.render())


if __name__ == "__main__":
    main()
