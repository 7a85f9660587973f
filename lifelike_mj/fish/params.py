"""Fish motion presets: the parameters of Satoi, Nakadai, Hoshino 2015, named with their units.

The paper gives the structure of its model but no values; every value here is ours, calibrated
against the paper's observations (docs/results.md). A preset is a JSON file in
``controllers/fish/`` (or any path)::

    {"format": "lifelike-mj/fish-preset", "version": 1, "name": "B-D",
     "description": "...", "parameters": {"P_a": 4.0, ..., "r_max_N": 0.03, ...}}

A preset may instead name another (``"same_as": "B-D"``): ``default`` is the calibrated ``B-D``.

Parameters (section numbers of the paper):

* Markov chain of the motion units (MU) S1 accelerate, S2 coast, S3 cruise, S4 brake (3.3): five
  non-negative weights ``P_a`` (S1 -> S1), ``P_b`` (S2, S3, S4 -> S1), ``P_c`` (-> S2),
  ``P_d`` (-> S3), ``P_e`` (-> S4); each row of the 4 x 4 matrix is normalised
  (:meth:`FishParams.transition_matrix`), redrawn every control step (``control_hz``). A preset may
  give its own 4 x 4 weights instead (``"transition": [[...], ...]``, rows from S1..S4).
* Accelerate (3.4.1, eq. 2-9): force magnitude ``r ~ U(r_min_N, r_max_N)`` (N); direction angles
  ``theta = 90 + U(-theta_range_deg, theta_range_deg) + balance_A_deg sgn(p) / (1 + exp(-balance_k_per_deg |p|))``
  and ``phi = 90 + U(-phi_range_deg, phi_range_deg)`` (deg), ``p`` the fish's pitch (deg, nose up
  > 0); angular acceleration = lateral or vertical component / (m R^2) with
  ``R = inertia_radius_m``.
* Drag (3.4.2-3.4.4): ``D = 1/2 rho C_D S v^2`` per body axis, ``rho = water_density_kg_m3``;
  areas ``S_v`` (m^2) and ``S_w`` (m^5) of the body's equivalent inertia box
  (``fish/scene.py``: :func:`box_areas`), with ``C_D = cd`` on the linear and ``cd_rot`` on the
  angular velocity (a rigid box turns far more freely than a fish with spread fins; ``cd_rot``
  stands for the fins); the brake MU adds ``brake_dS_v_m2`` and ``brake_dS_w_m5`` (per axis).
* Buoyancy (not in the paper): the water carries the fish's weight at a centre of buoyancy
  ``buoyancy_offset_m`` above its centre of mass, which rights roll and pitch. The paper's
  integration (section 3.5) turns only about the pitch and yaw axes; a rigid body in MuJoCo also
  couples yaw and pitch into roll (Euler's equations), and a real fish stays upright.
* Vision (3.6): rays of length ``vision_distance_m`` straight ahead and at ``vision_angle_deg`` to
  the sides, up and down.
* Wall avoidance (3.7): for ``avoid_duration_s`` after a wall is seen, ``P_a`` and ``P_b`` are
  multiplied by ``avoid_accel_gain`` (>= 1: the transition probability to accelerate rises), the
  force range by ``avoid_force_scale`` (< 1: smaller pushes) and each push turns
  ``avoid_turn_deg`` away from the wall (yaw, and pitch when the wall is above or below).
* ``runaway_speed_bl_s``: a fish whose running mean speed (time constant 10 s) exceeds this many
  body lengths per second stops the run with an error naming ``P_a`` or ``P_b`` (section 3.3: too high
  a transition probability to accelerate makes the speed diverge; in MuJoCo's stable integration it
  saturates instead, at a speed no damselfish keeps up).
* ``control_hz`` (the paper's 60 frames per second) and ``substeps`` (MuJoCo steps per control
  step).

Beyond the paper (fish that live together; every one off by default, so that the paper's presets swim as
before, bit for bit):

* **Kick rhythm** (``kick_gamma_shape`` > 0): a kick (a run of *accelerate* steps) starts only when the fish's
  timer runs out, and the next kick is due ``kick_floor_s`` plus a gamma-distributed wait (whole shape
  ``kick_gamma_shape`` up to 8, an Erlang wait; mean ``kick_mean_s - kick_floor_s``) after this one's start: a
  semi-Markov chain with a refractory floor, as burst-and-coast fish kick (Calovi et al. 2018). Between kicks the
  chain runs among coast, cruise and brake; the chain's own weight to stay in *accelerate* still sets how long a
  kick lasts. A fish avoiding a wall may kick as the paper's chain lets it, the floor still holding.
* **Social turns** (``social_attraction_rad``, ``social_alignment_rad``, ``social_depth_rad_per_bl`` > 0): at the
  start of each kick a fish turns toward and along the neighbours it sees (within ``social_range_bl`` body lengths,
  outside a rear blind sector of ``social_blind_deg``; no occlusion), heeding the ``social_neighbours`` most influential, in the
  functional forms of Calovi et al. (2018): attraction ``gamma_att ((d - d0) / l_att) / (1 + (d / l_att)^2) sin psi
  (1 + cos psi)`` (repulsion inside ``social_d0_bl``), alignment ``gamma_ali exp(-(d / l_ali)^2) sin dphi
  (1 + 0.3 cos 2 dphi) (1 + 0.6 cos psi - 0.32 cos 2 psi)`` (``d`` the distance, ``psi`` the neighbour's bearing,
  ``dphi`` its heading less the fish's, in its horizontal plane), and a pull to the neighbours' depth
  (``social_depth_rad_per_bl``, rad per body length, at most 0.5 rad). The sum (rad), times ``social_turn_gain`` (at most 80 deg),
  steers each push of the kick as a push at that angle would turn the fish (eq. 8-9: a lateral and a vertical
  share ``r sin`` of it), while its forward share stays as drawn: the kick still speeds the fish up. With
  ``social_speed_per_bl`` > 0 the kick's push is also scaled by ``1 + social_speed_per_bl`` times how far ahead (body
  lengths, along its heading) those neighbours are on average, within 0.5-1.5: a fish behind the others pushes
  harder, one ahead of them less (our addition: the functional forms above turn a fish but never change its speed).
* **Fish that touch** (``fish_contacts`` = 1): the fish's collision capsules collide with each other as well as with
  the tank (frictionless, as against the glass), so that no fish passes through another.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np

from lifelike_mj import checks
from lifelike_mj.errors import UserError
from lifelike_mj.paths import controllers_dir, load_named_json
from lifelike_mj.schema import check_header, unit_of, validate

FORMAT = "lifelike-mj/fish-preset"
#: The paper's four patterns (section 5.1.1) and the calibrated default.
PRESETS = ("NB-ND", "NB-D", "B-ND", "B-D", "default")
MU_NAMES = ("accelerate", "coast", "cruise", "brake")
#: The most fish a tank holds (a tank of 5,000 compiles in seconds; each fish is a MuJoCo body).
MAX_FISH = 5000
ACCELERATE, COAST, CRUISE, BRAKE = 0, 1, 2, 3


@dataclass(frozen=True)
class FishParams:
    """One motion preset (units in the names; see the module docstring). The defaults are the
    calibrated ``B-D`` pattern."""

    P_a: float = 4.0
    P_b: float = 0.035
    P_c: float = 0.6
    P_d: float = 0.2
    P_e: float = 0.2
    r_min_N: float = 0.01
    r_max_N: float = 0.03
    theta_range_deg: float = 30.0
    phi_range_deg: float = 80.0
    balance_A_deg: float = 10.0
    balance_k_per_deg: float = 0.2
    inertia_radius_m: float = 0.15
    water_density_kg_m3: float = 1000.0
    cd: float = 1.0
    cd_rot: float = 5.0
    buoyancy_offset_m: float = 0.001
    brake_dS_v_m2: tuple[float, float, float] = (6e-4, 0.0, 0.0)
    brake_dS_w_m5: tuple[float, float, float] = (0.0, 0.0, 0.0)
    vision_distance_m: float = 0.12
    vision_angle_deg: float = 30.0
    avoid_duration_s: float = 1.0
    avoid_accel_gain: float = 8.0
    avoid_force_scale: float = 0.5
    avoid_turn_deg: float = 45.0
    runaway_speed_bl_s: float = 4.5
    control_hz: float = 60.0
    substeps: int = 4
    # ---- beyond the paper (issue 28): off in the paper's presets, which then swim bit for bit as before ----
    kick_gamma_shape: int = 0
    kick_floor_s: float = 0.2
    kick_mean_s: float = 0.5
    social_attraction_rad: float = 0.0
    social_alignment_rad: float = 0.0
    social_depth_rad_per_bl: float = 0.0
    social_range_bl: float = 20.0
    social_blind_deg: float = 60.0
    social_d0_bl: float = 1.0
    social_l_att_bl: float = 6.5
    social_l_ali_bl: float = 6.5
    social_neighbours: int = 2
    social_turn_gain: float = 1.0
    social_speed_per_bl: float = 0.0
    fish_contacts: int = 0
    #: A Markov matrix of your own (4 x 4 non-negative weights, rows normalised; row i: from MU i)
    #: instead of the one P_a..P_e make; ``None``: the paper's structure.
    transition: tuple | None = None
    name: str = field(default="", compare=False)
    description: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        if self.transition is not None:
            try:
                t = np.array(self.transition, dtype=float)
            except (TypeError, ValueError):
                raise UserError("transition must be a 4 x 4 matrix of numbers.") from None
            if (t.shape != (4, 4) or not np.all(np.isfinite(t)) or np.any(t < 0) or np.any(t > MAX_TRANSITION_WEIGHT)
                    or np.any(t.sum(axis=1) <= 0)):
                raise UserError(f"transition must be a 4 x 4 matrix of weights in [0, {MAX_TRANSITION_WEIGHT:g}], "
                                "each row with a positive sum (rows: from accelerate, coast, cruise, brake), got "
                                f"{self.transition!r}.")
            object.__setattr__(self, "transition", tuple(tuple(float(x) for x in row) for row in t))
        for f in fields(self):
            if f.name in ("name", "description", "transition"):
                continue
            v = getattr(self, f.name)
            vals = v if isinstance(v, tuple) else (v,)
            for x in vals:
                if not checks.is_number(x) or not math.isfinite(x):
                    raise UserError(f"fish parameter {f.name} must be a finite number, got {v!r}.")
            if isinstance(v, tuple) and len(v) != 3:
                raise UserError(f"fish parameter {f.name} must have 3 values (x, y, z), got {len(v)}.")
        probs = ("P_a", "P_b", "P_c", "P_d", "P_e")
        for k in probs:
            if getattr(self, k) < 0:
                raise UserError(f"transition weight {k} must not be negative, got {getattr(self, k)}.")
        if self.P_a + self.P_c + self.P_d + self.P_e <= 0 or self.P_b + self.P_c + self.P_d + self.P_e <= 0:
            raise UserError("transition weights P_a..P_e are all zero in a row; at least one must be positive.")
        if self.r_min_N < 0:
            raise UserError(f"r_min_N must not be negative, got {self.r_min_N}.")
        if self.r_min_N > self.r_max_N:
            raise UserError(f"r_min_N ({self.r_min_N}) must not exceed r_max_N ({self.r_max_N}).")
        positive = ("inertia_radius_m", "water_density_kg_m3", "cd", "cd_rot", "vision_distance_m", "control_hz",
                    "runaway_speed_bl_s", "avoid_force_scale")
        for k in positive:
            if getattr(self, k) <= 0:
                raise UserError(f"fish parameter {k} must be positive, got {getattr(self, k)}.")
        for k in ("buoyancy_offset_m", "theta_range_deg", "phi_range_deg", "balance_A_deg", "balance_k_per_deg",
                  "avoid_duration_s", "avoid_turn_deg"):
            if getattr(self, k) < 0:
                raise UserError(f"fish parameter {k} must not be negative, got {getattr(self, k)}.")
        if min(self.brake_dS_v_m2) < 0 or min(self.brake_dS_w_m5) < 0:
            raise UserError("brake area increments must not be negative.")
        if self.avoid_accel_gain < 1:
            raise UserError(f"avoid_accel_gain must be at least 1 (avoidance raises the chance to accelerate), "
                            f"got {self.avoid_accel_gain}.")
        if self.avoid_force_scale > 1:
            raise UserError(f"avoid_force_scale must not exceed 1 (avoidance lowers r_min and r_max), "
                            f"got {self.avoid_force_scale}.")
        if not (0 < self.vision_angle_deg < 90):
            raise UserError(f"vision_angle_deg must lie in (0, 90), got {self.vision_angle_deg}.")
        if int(self.substeps) != self.substeps or not 1 <= self.substeps <= 100:
            raise UserError(f"substeps must be a whole number from 1 to 100, got {self.substeps}.")
        if self.kick_gamma_shape > 0 and not self.kick_mean_s > self.kick_floor_s:
            raise UserError(f"kick_mean_s ({self.kick_mean_s:g} s) must exceed kick_floor_s ({self.kick_floor_s:g} s): "
                            "the mean interval between kicks is the floor plus a gamma-distributed wait.")
        if self.fish_contacts not in (0, 1):
            raise UserError(f"fish_contacts is 0 or 1 (whether fish collide with each other), got {self.fish_contacts}.")
        if int(self.kick_gamma_shape) != self.kick_gamma_shape:
            raise UserError(f"kick_gamma_shape must be a whole number from 0 (the paper's chain) to 8, got "
                            f"{self.kick_gamma_shape}.")
        if int(self.social_neighbours) != self.social_neighbours:
            raise UserError(f"social_neighbours must be a whole number, got {self.social_neighbours}.")
        if not 1.0 <= self.control_hz <= 10_000.0:
            raise UserError(f"control_hz must be in [1, 10000] Hz (the paper's is 60), got {self.control_hz}.")
        for k, (lo, hi, lo_open) in RANGES.items():  # the same bounds as the preset file's schema
            for x in (v if isinstance(v := getattr(self, k), tuple) else (v,)):
                checks.number(f"fish parameter {k}", x, lo, hi, lo_open=lo_open, unit=unit_of(k))

    # ---- the Markov chain (section 3.3) ----
    def transition_matrix(self, avoiding: bool = False) -> np.ndarray:
        """The 4 x 4 row-stochastic matrix ``T[i, j] = P(next MU j | MU i)`` (Satoi 2015 section 3.3):
        from ``P_a``..``P_e``, or the preset's own ``transition`` weights. While avoiding a wall
        (section 3.7) the weights to accelerate (column 0) are multiplied by ``avoid_accel_gain``."""
        g = self.avoid_accel_gain if avoiding else 1.0
        if self.transition is not None:
            rows = np.array(self.transition, dtype=float)
            rows[:, 0] *= g
            return rows / rows.sum(axis=1, keepdims=True)
        pa, pb = g * self.P_a, g * self.P_b
        rows = np.array([[pa, self.P_c, self.P_d, self.P_e]] + [[pb, self.P_c, self.P_d, self.P_e]] * 3, dtype=float)
        return rows / rows.sum(axis=1, keepdims=True)

    def stationary(self, avoiding: bool = False) -> np.ndarray:
        """Stationary distribution of :meth:`transition_matrix` (share of control steps per MU)."""
        T = self.transition_matrix(avoiding)
        w, v = np.linalg.eig(T.T)
        p = np.real(v[:, np.argmin(np.abs(w - 1.0))])
        return p / p.sum()

    @property
    def social(self) -> bool:
        """Whether the fish heed each other (any of the social terms above zero; module docstring)."""
        return max(self.social_attraction_rad, self.social_alignment_rad, self.social_depth_rad_per_bl,
                   self.social_speed_per_bl) > 0.0

    @property
    def control_dt_s(self) -> float:
        return 1.0 / self.control_hz

    @property
    def timestep_s(self) -> float:
        return 1.0 / (self.control_hz * self.substeps)

    def to_dict(self) -> dict:
        d = asdict(self)
        d.pop("name")
        d.pop("description")
        if d["transition"] is None:
            d.pop("transition")
        for k, v in d.items():
            if isinstance(v, tuple):
                d[k] = [list(r) if isinstance(r, tuple) else r for r in v]
        return d

    def to_file_dict(self) -> dict:
        return {"format": FORMAT, "version": 1, "name": self.name, "description": self.description,
                "parameters": self.to_dict()}


_FIELDS = {f.name for f in fields(FishParams)} - {"name", "description"}

#: Every number's range ``(low, high, low excluded)``: what :class:`FishParams` accepts and the preset file's
#: schema says (:func:`json_schema`). The highs are far beyond a fish (a force of 1000 N on a 3 g fish) and
#: keep every number that reaches the compiled tank finite; the tank reports a divergence long before.
RANGES: dict[str, tuple[float, float, bool]] = {
    **{k: (0.0, 1e6, False) for k in ("P_a", "P_b", "P_c", "P_d", "P_e")},
    "r_min_N": (0.0, 1000.0, False), "r_max_N": (0.0, 1000.0, False),
    "theta_range_deg": (0.0, 360.0, False), "phi_range_deg": (0.0, 360.0, False),
    "balance_A_deg": (0.0, 180.0, False), "balance_k_per_deg": (0.0, 1000.0, False),
    "inertia_radius_m": (0.0, 10.0, True), "water_density_kg_m3": (0.0, 1e5, True), "cd": (0.0, 1000.0, True),
    "cd_rot": (0.0, 1e4, True), "buoyancy_offset_m": (0.0, 1.0, False),
    "brake_dS_v_m2": (0.0, 1.0, False), "brake_dS_w_m5": (0.0, 1.0, False),
    "vision_distance_m": (0.0, 100.0, True), "vision_angle_deg": (0.0, 90.0, True),
    "avoid_duration_s": (0.0, 3600.0, False), "avoid_accel_gain": (1.0, 1e6, False),
    "avoid_force_scale": (0.0, 1.0, True), "avoid_turn_deg": (0.0, 180.0, False),
    "runaway_speed_bl_s": (0.0, 1e4, True), "control_hz": (1.0, 10_000.0, False), "substeps": (1.0, 100.0, False),
    "kick_gamma_shape": (0.0, 8.0, False), "kick_floor_s": (0.0, 60.0, False), "kick_mean_s": (0.0, 60.0, True),
    "social_attraction_rad": (0.0, 10.0, False), "social_alignment_rad": (0.0, 10.0, False),
    "social_depth_rad_per_bl": (0.0, 10.0, False),
    "social_range_bl": (0.0, 1e4, True), "social_blind_deg": (0.0, 360.0, False), "social_d0_bl": (0.0, 100.0, False),
    "social_l_att_bl": (0.0, 1e4, True), "social_l_ali_bl": (0.0, 1e4, True), "social_neighbours": (1.0, 1000.0, False),
    "social_turn_gain": (0.0, 100.0, False), "social_speed_per_bl": (0.0, 10.0, False),
    "fish_contacts": (0.0, 1.0, False),
}
#: A transition weight's largest value (the matrix's rows are normalised).
MAX_TRANSITION_WEIGHT = 1e6


def params_from_dict(data: dict, name: str = "") -> FishParams:
    """Build :class:`FishParams` from a preset file's content (unknown keys are an error)."""
    where = f"fish preset {name}".strip()
    check_header(data, FORMAT, where, kind="fish preset")
    validate(data, json_schema(), where)
    kw = {k: (tuple(v) if isinstance(v, list) else v) for k, v in data["parameters"].items()}
    return FishParams(**kw, name=data.get("name", name), description=data.get("description", ""))


def preset_path(name: str) -> Path:
    return controllers_dir() / "fish" / f"{name}.json"


def load_preset(name_or_path: str | Path | None = None, _seen: tuple[str, ...] = ()) -> FishParams:
    """A preset by name (the paper's ``NB-ND``, ``NB-D``, ``B-ND``, ``B-D``, ``default``; ``school``, ``shoal``, ``pair``)
    or by path to a file."""
    ref = "default" if name_or_path is None else str(name_or_path)
    data, p = load_named_json("fish", ref, "fish preset")
    if isinstance(data, dict) and "same_as" in data:
        where = f"fish preset {p.stem}"
        check_header(data, FORMAT, where, kind="fish preset")
        validate(data, json_schema(), where)
        target = data["same_as"]
        if target in _seen:
            raise UserError(f"fish preset {ref} refers back to itself through 'same_as'.")
        base = load_preset(target, (*_seen, ref))
        return FishParams(**{k: getattr(base, k) for k in _FIELDS}, name=data.get("name", p.stem),
                          description=data.get("description", base.description))
    return params_from_dict(data, p.stem)


def preset_names() -> list[str]:
    """Names of the presets shipped in ``controllers/fish/``."""
    from lifelike_mj.paths import shipped_names

    return shipped_names("fish")


def json_schema() -> dict:
    """The JSON Schema of a fish preset file (``docs/schemas/fish-preset.schema.json``)."""
    from lifelike_mj.schema import document_schema, number, unit_of

    def ranged(k: str, description: str) -> dict:
        lo, hi, lo_open = RANGES[k]
        return number(description, None if lo_open else lo, hi, exclusive_minimum=lo if lo_open else None)

    props: dict = {}
    for f in fields(FishParams):
        if f.name in ("name", "description"):
            continue
        if f.name == "transition":
            props[f.name] = {"type": "array", "minItems": 4, "maxItems": 4, "description": "4 x 4 Markov weights, "
                             "rows from accelerate, coast, cruise, brake (instead of P_a..P_e)",
                             "items": {"type": "array", "minItems": 4, "maxItems": 4,
                                       "items": number("", 0, MAX_TRANSITION_WEIGHT)}}
        elif f.name.startswith("brake_dS"):
            props[f.name] = {"type": "array", "minItems": 3, "maxItems": 3, "items": ranged(f.name, ""),
                             "description": f"per body axis (x, y, z), {unit_of(f.name)}"}
        elif f.name == "substeps":
            props[f.name] = {"type": "integer", "minimum": 1, "maximum": 100, "description": "MuJoCo steps per control step"}
        elif f.name == "kick_gamma_shape":
            props[f.name] = {"type": "integer", "minimum": 0, "maximum": 8,
                             "description": "0: the paper's chain; else the kick rhythm's gamma (Erlang) shape"}
        elif f.name == "fish_contacts":
            props[f.name] = {"type": "integer", "minimum": 0, "maximum": 1,
                             "description": "1: the fish's collision capsules also collide with each other"}
        elif f.name == "social_neighbours":
            props[f.name] = {"type": "integer", "minimum": 1, "maximum": 1000,
                             "description": "how many neighbours a fish heeds at a kick (the most influential)"}
        elif f.name == "control_hz":
            props[f.name] = ranged(f.name, "control steps per second, Hz (the paper: 60)")
        else:
            props[f.name] = ranged(f.name, unit_of(f.name) and f"unit: {unit_of(f.name)}")
    params = {"type": "object", "properties": props, "additionalProperties": False,
              "description": "every parameter is optional; missing ones take the calibrated default (B-D)"}
    schema = document_schema(FORMAT, "lifelike-mj fish preset", {"parameters": params, "same_as": {"type": "string"}},
                             [], "Satoi 2015 motion units: a preset's parameters, or same_as another preset.")
    schema["if"] = {"required": ["same_as"]}
    schema["then"] = {"properties": {"parameters": False}}
    schema["else"] = {"required": ["parameters"]}
    return schema
