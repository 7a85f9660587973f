"""3D controllers: what the network sees and does, and the controller file.

A 3D controller sees the body's attitude and motion relative to a **reference** (a heading, an altitude
and a forward speed) and answers with changes of the kinematics around a **base command**
(:class:`~lifelike_mj.butterfly.flight3d.kinematics.KinematicsCommand`). The reference comes from a **task**:
a schedule of references over time (level flight, turns) or a course of waypoints (the reference then
points at the next waypoint). The network never sees where it is, only how far it is off.

Observation (:data:`OBS_NAMES`; SI units, in the heading frame: forward, left, up):
roll, pitch, heading error (reference less yaw, wrapped to ``(-pi, pi]``), the thorax's angular
velocity (roll, pitch, yaw rates in its own axes), forward-speed error, sideways speed, climb rate,
altitude error (clipped to +-1 m) and the forward speed asked (the reference's own speed, m/s). A network has
either the first ten inputs (the shipped ``monarch``) or all eleven: a network that also sees the speed asked can set
its trim for that speed (a lower body for a faster flight, as a butterfly's body angle falls with its speed;
Dudley 1990) instead of holding it off by a speed error, which a network without memory must keep to trim
differently. A controller's ``inputs`` say what the forward and sideways speeds are
measured against: ``"ground"`` (the shipped ``monarch``) or ``"air"`` (the air around the
butterfly, wind and gusts included, as a butterfly's antennae sense it; the speed reference is then an air
speed). The climb rate and the altitude are always the ground's.

Action (:data:`ACTION_NAMES`): nine numbers ``u`` in ``(-1, 1)`` (the network's last layer through
``tanh``), each scaled by its entry of ``scale`` (rad; Hz for the frequency) and added to the base
command: the wings' stroke offset and amplitude, both wings alike (``sym``) and left against right
(``asym``), the feathering mean (``sym``, ``asym``), the feathering amplitude, the abdomen's mean angle
and the flap frequency. The kinematics follow each
new command smoothly (the filter of :mod:`~lifelike_mj.butterfly.flight3d.kinematics`).

Networks: ``layers = [10 or 11, ..., 9]``, hidden neurons ``tanh``; ``[10, 9]`` and ``[11, 9]`` are linear policies.

Behaviours (:data:`MODES`): beside its flight network a controller may carry networks of the same shape for the parts
of a flight that ask for another way of flying, as an animal's motor patterns change between cruising, landing and
taking off: ``land`` flies a landing's last ``from_m`` (m, horizontally from the flower's axis), ``take_off`` the
first ``for_s`` (s) after a take-off. Where a controller has none, its flight network flies throughout.
"""

from __future__ import annotations

import math

import numpy as np

OBS_NAMES = ("roll_rad", "pitch_rad", "heading_error_rad", "roll_rate_rad_s", "pitch_rate_rad_s",
             "yaw_rate_rad_s", "speed_error_m_s", "sideways_m_s", "climb_m_s", "altitude_error_m", "speed_ref_m_s")
ACTION_NAMES = ("offset_sym", "offset_asym", "amplitude_sym", "amplitude_asym", "feather_sym", "feather_asym",
                "feather_amplitude", "abdomen_mean", "frequency")
N_OBS, N_ACT = len(OBS_NAMES), len(ACTION_NAMES)
#: How many inputs a network may have: the first ten observations, or all of them (module docstring).
INPUT_COUNTS = (N_OBS - 1, N_OBS)
#: Altitude errors beyond this (m) are seen as this.
ALTITUDE_CLIP_M = 1.0
#: What the network's inputs are divided by (the observation's units): angles by 1 rad, rates by 10 rad/s,
#: speeds by 1 m/s, the altitude error by 0.5 m, so that every input is of order one in flight.
INPUT_SCALE = np.array([1.0, 1.0, 1.0, 10.0, 10.0, 10.0, 1.0, 1.0, 1.0, 0.5, 1.0])

def n_weights(layers) -> int:
    """How many weights a network of ``layers`` has (biases included)."""
    return int(sum((layers[k - 1] + 1) * layers[k] for k in range(1, len(layers))))


# ---- controller files ------------------------------------------------------------------------

FORMAT = "lifelike-mj/butterfly3d-controller"
#: Bounds of a 3D controller (files and Python alike; every one of these numbers reaches the compiled loop):
#: at most this many layers (inputs and outputs included), neurons per hidden layer, size of a weight, steps
#: between two runs of the network, and rate at which the kinematics follow a command (rad/s).
MAX_LAYERS, MAX_WIDTH, MAX_WEIGHT, MAX_EVERY, MAX_OMEGA_C = 6, 256, 1.0e6, 12_000, 1.0e4
#: What a controller's forward and sideways speeds are measured against (module docstring).
INPUTS = ("ground", "air")
#: Bounds of the speed boost (module docstring): its gain (1/s) and its largest bound (m/s).
MAX_SPEED_GAIN, MAX_BOOST_M_S = 100.0, 10.0
#: The wing-force laws a controller can be evolved with and fly (those of the model's callback that act over the
#: wing's area: :data:`~lifelike_mj.butterfly.flight3d.model.FORCE_LAWS` less ``none`` and the paper's ``tip``).
FORCE_LAWS_FLOWN = ("exact", "strip", "quasi_steady", "calibrated")
#: The behaviour networks a controller may carry (module docstring), each with the name of its reach: ``land`` from
#: ``from_m`` (m) out, ``take_off`` for ``for_s`` (s); and the reach a new one gets.
MODES = {"land": "from_m", "take_off": "for_s"}
MODE_REACH = {"land": 0.6, "take_off": 1.0}
#: The kinds of 3D controller file: a network (the default, :class:`Controller3D`) or a controller designed from the
#: averaged model (:mod:`~lifelike_mj.butterfly.flight3d.designed`).
KINDS = ("network", "designed")
#: A controller's networks in the compiled loop's order (:meth:`Controller3D.all_weights`,
#: :func:`~lifelike_mj.butterfly.flight3d.loop.behaviour`'s answer indexes it): the flight network, then the behaviours.
NETWORKS = ("flight", *MODES)
#: The largest reach of a behaviour network (m or s).
MAX_REACH = 100.0
#: The largest 3D controller file (bytes), checked before it is read: the largest legitimate controller as lifelike-mj
#: writes it (indented JSON, one number a line): a flight network of :data:`MAX_LAYERS` layers of :data:`MAX_WIDTH`
#: neurons and a behaviour network of its shape for each of :data:`MODES`, every weight as long as a float's text can
#: be (24 characters: ``-2.2250738585072014e-308``) on a line indented 4 (the flight network's) or 8 spaces (a
#: behaviour's), and 2 MB for the rest (the base, the scales and the provenance: some 10,000 generations' fitness
#: history). 21.9 MB.
MAX_FILE_BYTES = (n_weights([N_OBS, *[MAX_WIDTH] * (MAX_LAYERS - 2), N_ACT]) * ((4 + 24 + 2) + len(MODES) * (8 + 24 + 2))
                  + 2_000_000)
#: Default ``scale`` of the actions (rad; Hz for the frequency).
DEFAULT_SCALE = {"offset_sym": 0.3, "offset_asym": 0.3, "amplitude_sym": 0.3, "amplitude_asym": 0.3, "feather_sym": 0.5,
                 "feather_asym": 0.3, "feather_amplitude": 0.3, "abdomen_mean": 0.8, "frequency": 3.0}


def default_base(animal: str = "swallowtail"):
    """The base command a new 3D controller starts from, per butterfly.

    * ``"swallowtail"`` (the shipped controllers'): the paper's 10 Hz flap over [-60, 75] deg (Oe 2010 section 6),
      feathered by 0.3 rad a quarter beat ahead (leading edge down on the downstroke), the abdomen still.
    * ``"monarch"``: the filmed monarch's envelope (the FWUAV group's fit of a free flight): 10.2 Hz; a 120 deg
      stroke (+-60 deg) about +8 deg, so that the wings stop 44 deg apart at the top (a cruising butterfly's
      dorsal gap, 35-50 deg, no clap) and reach -52 deg at the bottom; feathering +-39 deg a quarter beat ahead;
      the abdomen flexed 17 deg down (its mean ventral flexion), swinging +-14 deg, most flexed just after the
      top of the stroke (roughly against the wings)."""
    from lifelike_mj.butterfly.flight3d.animals import animal as _animal
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand

    if _animal(animal).name == "monarch":
        amp, off = math.radians(60.0), math.radians(8.0)
        feather = math.radians(39.0)
        return KinematicsCommand(frequency_hz=10.2, offset_left=off, offset_right=off, amplitude_left=amp,
                                 amplitude_right=amp, feather_amplitude_left=feather, feather_amplitude_right=feather,
                                 feather_phase=-math.pi / 2, abdomen_mean=-math.radians(17.0),
                                 abdomen_amplitude=math.radians(14.0), abdomen_phase=math.pi - 0.6)
    return KinematicsCommand(feather_amplitude_left=0.3, feather_amplitude_right=0.3, feather_phase=-math.pi / 2)


class Controller3D:
    """A 3D controller: a network from the observation to the action (module docstring), the base command
    and the actions' scales, how often it runs (``every`` steps), how fast the kinematics follow
    (``omega_c_rad_s``) and what its speeds are measured against (``inputs``: ``"ground"`` or ``"air"``), with
    its provenance, the butterfly it flies (``animal``, one of
    :data:`~lifelike_mj.butterfly.flight3d.animals.ANIMALS`) and the wing-force law it was evolved with
    (``force_law``: ``"exact"``, ``"strip"``, ``"quasi_steady"`` or ``"calibrated"``; flights take it unless told
    otherwise). Plain
    data: :meth:`to_dict` / :func:`controller_from_dict`."""

    def __init__(self, layers, weights, base=None, scale: dict | None = None, every: int = 1,
                 omega_c_rad_s: float = 2.0 * math.pi * 10.0, provenance: dict | None = None, name: str = "",
                 inputs: str = "ground", animal: str = "swallowtail", force_law: str = "exact",
                 modes: dict | None = None, speed_gain_per_s: float = 0.0, speed_boost_max_m_s: float = 1.5) -> None:
        from lifelike_mj import checks
        from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
        from lifelike_mj.errors import UserError

        if not isinstance(name, str):
            raise UserError(f"a 3D controller's name is a text, got {_short(name)}.")
        self.name = name
        where = f"3D controller {name}" if name else "3D controller"
        layers = _check_layers(layers, where)
        self.layers = np.array(layers, dtype=np.int64)
        try:
            if weights is None or isinstance(weights, (str, bytes, dict)):
                raise TypeError
            self.weights = np.ascontiguousarray(weights, dtype=np.float64).reshape(-1)
        except (TypeError, ValueError):
            raise UserError(f"{where}: the weights must be numbers, got {_short(weights)}.") from None
        _check_count(where, layers, len(self.weights), bool(np.all(np.abs(self.weights) <= MAX_WEIGHT)))
        self.base = base if base is not None else default_base(animal)
        if not isinstance(self.base, KinematicsCommand):
            raise UserError(f"{where}: the base is a KinematicsCommand, got {self.base!r}.")
        if scale is not None and not isinstance(scale, dict):
            raise UserError(f"{where}: scale is a mapping of action names to numbers, got {scale!r}.")
        scale = dict(DEFAULT_SCALE, **(scale or {}))
        unknown = set(scale) - set(ACTION_NAMES)
        if unknown:
            from lifelike_mj.errors import unknown_name

            raise unknown_name(f"{where}: unknown action", sorted(unknown, key=str)[0], ACTION_NAMES, "in scale")
        self.scale = np.array([checks.number(f"scale of {a}", scale[a], 0.0, math.pi) for a in ACTION_NAMES])
        self.every = checks.whole("every", every, 1, MAX_EVERY)
        self.omega_c_rad_s = checks.number("omega_c_rad_s", omega_c_rad_s, 0.0, MAX_OMEGA_C, lo_open=True, unit="rad/s")
        if inputs not in INPUTS:
            raise UserError(f"{where}: inputs are {' or '.join(repr(v) for v in INPUTS)}, got {inputs!r}.")
        self.inputs = inputs
        self.speed_gain_per_s = checks.number("speed_gain_per_s", speed_gain_per_s, 0.0, MAX_SPEED_GAIN, unit="1/s")
        self.speed_boost_max_m_s = checks.number("speed_boost_max_m_s", speed_boost_max_m_s, 0.0, MAX_BOOST_M_S,
                                                 unit="m/s")
        if self.speed_gain_per_s > 0.0 and int(self.layers[0]) != N_OBS:
            raise UserError(f"{where}: a speed boost (speed_gain_per_s) needs a network that sees the speed asked "
                            f"({N_OBS} inputs).")
        from lifelike_mj.butterfly.flight3d.animals import animal as _animal

        self.animal = _animal(animal).name
        if force_law not in FORCE_LAWS_FLOWN:
            raise UserError(f"{where}: force_law is {', '.join(repr(v) for v in FORCE_LAWS_FLOWN)}, got {force_law!r}.")
        self.force_law = force_law
        if provenance is not None and not isinstance(provenance, dict):
            raise UserError(f"{where}: provenance is a mapping (the record of how it was made), got {_short(provenance)}.")
        self.provenance = dict(provenance or {})
        if modes is not None and not isinstance(modes, dict):
            raise UserError(f"{where}: modes is a mapping of behaviours to networks, got {_short(modes)}.")
        #: The behaviour networks (module docstring): name -> ``{"weights": array, reach name: float}``.
        self.modes = {}
        for mode, spec in (modes or {}).items():
            if mode not in MODES:
                from lifelike_mj.errors import unknown_name

                raise unknown_name(f"{where}: unknown behaviour", mode, tuple(MODES), "in modes")
            reach = MODES[mode]
            if not isinstance(spec, dict) or set(spec) - {"weights", reach}:
                raise UserError(f"{where}: the {mode} behaviour is a mapping of weights and {reach}, got {_short(spec)}.")
            try:
                if spec.get("weights") is None or isinstance(spec["weights"], (str, bytes, dict)):
                    raise TypeError
                w = np.ascontiguousarray(spec["weights"], dtype=np.float64).reshape(-1)
            except (TypeError, ValueError):
                raise UserError(f"{where}: the {mode} behaviour's weights must be numbers.") from None
            _check_count(where, layers, len(w), bool(np.all(np.abs(w) <= MAX_WEIGHT)), mode)
            self.modes[mode] = {"weights": w, reach: checks.number(f"{where}: the {mode} behaviour's {reach}",
                                                                    spec.get(reach, MODE_REACH[mode]), 0.0, MAX_REACH,
                                                                    lo_open=True, unit="m" if mode == "land" else "s")}

    def to_dict(self) -> dict:
        from dataclasses import asdict

        return {"format": FORMAT, "version": 1, "layers": [int(v) for v in self.layers],
                "weights": [float(v) for v in self.weights], "base": asdict(self.base),
                "scale": dict(zip(ACTION_NAMES, (float(v) for v in self.scale))), "every": self.every,
                "omega_c_rad_s": self.omega_c_rad_s, "inputs": self.inputs, "animal": self.animal,
                "force_law": self.force_law, "provenance": self.provenance,
                **({"speed_gain_per_s": self.speed_gain_per_s, "speed_boost_max_m_s": self.speed_boost_max_m_s}
                   if self.speed_gain_per_s > 0.0 else {}),
                **({"modes": {k: {"weights": [float(v) for v in m["weights"]], MODES[k]: m[MODES[k]]}
                              for k, m in self.modes.items()}} if self.modes else {})}

    @property
    def air_inputs(self) -> bool:
        """Whether the network's speeds are through the air (the compiled loop's flag)."""
        return self.inputs == "air"

    def loop_options(self) -> np.ndarray:
        """What the compiled loop needs beside the networks: whether the speeds are through the air (1 or 0), the speed
        boost's gain (1/s) and bound (m/s)."""
        return np.array([float(self.air_inputs), self.speed_gain_per_s, self.speed_boost_max_m_s])

    def replace(self, **changes) -> Controller3D:
        """The same controller with the given constructor arguments changed (each checked as by the constructor)."""
        kw = {"layers": self.layers, "weights": self.weights, "base": self.base,
              "scale": dict(zip(ACTION_NAMES, self.scale)), "every": self.every, "omega_c_rad_s": self.omega_c_rad_s,
              "provenance": self.provenance, "name": self.name, "inputs": self.inputs, "animal": self.animal,
              "force_law": self.force_law, "modes": self.modes, "speed_gain_per_s": self.speed_gain_per_s,
              "speed_boost_max_m_s": self.speed_boost_max_m_s}
        unknown = set(changes) - set(kw)
        if unknown:
            raise TypeError(f"replace: unknown argument {sorted(unknown)[0]!r}")
        kw.update(changes)
        return Controller3D(**kw)

    @property
    def sees_speed_asked(self) -> bool:
        """Whether the networks have the eleventh input, the forward speed asked (module docstring)."""
        return int(self.layers[0]) == N_OBS

    def with_speed_input(self, pitch_deg_per_m_s: float = 0.0, about_m_s: float = 1.0) -> Controller3D:
        """The same controller whose networks also see the forward speed asked (the eleventh observation). With the
        defaults each first-layer neuron's weight on it is zero: it flies exactly as before until those weights change.
        ``pitch_deg_per_m_s`` (deg per m/s): a **pitch schedule** instead. Each first-layer neuron's weight on the speed
        asked is its weight on the pitch times that many rad per m/s, and its bias less that weight times
        ``about_m_s``: the networks then see the pitch as if it were ``pitch_deg_per_m_s`` higher per m/s asked above
        ``about_m_s`` (lower below), so that a network that holds its pitch flies its body that much lower per m/s
        asked. The same as before at ``about_m_s``. A controller that sees the speed asked already is returned as it
        is."""
        from lifelike_mj import checks

        if self.sees_speed_asked:
            return self
        n_in, n_first = int(self.layers[0]), int(self.layers[1])
        first = (n_in + 1) * n_first
        k = math.radians(checks.number("pitch_deg_per_m_s", pitch_deg_per_m_s, -90.0, 90.0, unit="deg per m/s"))
        v0 = checks.number("about_m_s", about_m_s, 0.0, 100.0, unit="m/s")
        pitch = OBS_NAMES.index("pitch_rad")

        def padded(w):
            rows = np.asarray(w[:first]).reshape(n_first, n_in + 1)
            speed = rows[:, pitch] * k
            rows = np.concatenate([rows[:, :n_in], speed[:, None], rows[:, n_in:] - (speed * v0)[:, None]], axis=1)
            return np.concatenate([rows.reshape(-1), w[first:]])

        modes = {k_: {**m, "weights": padded(m["weights"])} for k_, m in self.modes.items()}
        return self.replace(layers=[N_OBS, *[int(v) for v in self.layers[1:]]], weights=padded(self.weights),
                            modes=modes)

    def with_weights(self, weights, inputs: str | None = None) -> Controller3D:
        """The same controller with other weights of its flight network (and, given ``inputs``, other inputs)."""
        return self.replace(weights=weights, inputs=inputs or self.inputs)

    def with_mode(self, mode: str, weights, reach: float | None = None) -> Controller3D:
        """The same controller with the behaviour network ``mode`` (:data:`MODES`) set to ``weights`` and its reach
        (m or s; default: the one it has, else :data:`MODE_REACH`)."""
        old = self.modes.get(mode, {})
        reach = reach if reach is not None else old.get(MODES.get(mode, ""), MODE_REACH.get(mode))
        return self.replace(modes={**self.modes, mode: {"weights": weights, MODES.get(mode, "reach"): reach}})

    def mode_weights(self, mode: str) -> np.ndarray:
        """The weights that fly behaviour ``mode`` (:data:`MODES`): its own network's, else the flight network's."""
        if mode not in MODES:
            from lifelike_mj.errors import unknown_name

            raise unknown_name("unknown behaviour", mode, tuple(MODES))
        return self.modes[mode]["weights"] if mode in self.modes else self.weights

    def all_weights(self) -> np.ndarray:
        """The weights the compiled loop takes: the flight network's, then each behaviour's in the order of
        :data:`MODES` (a behaviour without a network of its own repeats the flight network's)."""
        return np.concatenate([self.weights, *(self.mode_weights(m) for m in MODES)])

    def mode_reach(self) -> np.ndarray:
        """Each behaviour's reach in the order of :data:`MODES` (m, s): 0 where it has no network of its own."""
        return np.array([self.modes[m][r] if m in self.modes else 0.0 for m, r in MODES.items()])


def _short(v: object) -> str:
    """``repr(v)``, shortened for a sentence (a list of millions of weights is shown by its first few)."""
    import reprlib

    return reprlib.repr(v)


def _check_layers(layers: object, where: str) -> list[int]:
    """``layers`` as a list of ints, or a :class:`~lifelike_mj.errors.UserError`: from 10 or 11 inputs to 9 outputs, at
    most :data:`MAX_LAYERS` layers of at most :data:`MAX_WIDTH` neurons (a long list is refused by its length alone)."""
    from lifelike_mj import checks
    from lifelike_mj.errors import UserError

    try:
        given = list(layers)  # type: ignore[call-overload]
    except TypeError:
        given = None
    ok = (given is not None and 2 <= len(given) <= MAX_LAYERS and all(checks.is_whole(v) for v in given)
          and given[0] in INPUT_COUNTS and given[-1] == N_ACT and all(1 <= v <= MAX_WIDTH for v in given))
    if not ok:
        raise UserError(f"{where}: layers must be whole numbers running from {INPUT_COUNTS[0]} or {INPUT_COUNTS[1]} "
                        f"inputs to {N_ACT} outputs, "
                        f"at most {MAX_LAYERS} layers of at most {MAX_WIDTH} neurons, got {_short(layers)}.")
    return [int(v) for v in given]


def _check_count(where: str, layers: list[int], got: int, within: bool = True, mode: str = "") -> None:
    """A :class:`~lifelike_mj.errors.UserError` unless a network of ``layers`` (the flight network, or the behaviour
    ``mode``'s, which has its shape) has ``got`` weights, all ``within`` :data:`MAX_WEIGHT`."""
    from lifelike_mj.errors import UserError

    n = n_weights(layers)
    if got == n and within:
        return
    tail = f"got {got}" if got != n else f"got {got} with one beyond"
    if mode:
        raise UserError(f"{where}: the {mode} behaviour needs {n} finite weights (its network is the flight network's "
                        f"shape, layers {layers}), each within +-{MAX_WEIGHT:g}, {tail}.")
    raise UserError(f"{where}: layers {layers} need {n} finite weights, each within +-{MAX_WEIGHT:g}, {tail}.")


def json_schema() -> dict:
    """The JSON Schema of a 3D controller file (``docs/schemas/butterfly3d-controller.schema.json``): what
    :func:`controller_from_dict` enforces before building the controller."""
    from lifelike_mj.butterfly.flight3d.animals import ANIMALS
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.schema import document_schema, number

    max_weights = n_weights([N_OBS, *[MAX_WIDTH] * (MAX_LAYERS - 2), N_ACT])
    props = {
        "kind": {"const": "network", "description": "a network controller (the default); a designed controller has "
                 "its own schema (butterfly3d-designed)"},
        "layers": {"type": "array", "minItems": 2, "maxItems": MAX_LAYERS,
                   "items": {"type": "integer", "minimum": 1, "maximum": MAX_WIDTH},
                   "description": f"neurons per layer, from the first {INPUT_COUNTS[0]} observations or all "
                                  f"{N_OBS} to the {N_ACT} actions"},
        "weights": {"type": "array", "maxItems": max_weights, "items": number("", -MAX_WEIGHT, MAX_WEIGHT),
                    "description": "per layer, per neuron: its input weights, then its bias"},
        "base": KinematicsCommand.json_schema(),
        "scale": {"type": "object", "additionalProperties": False, "description": "each action's full scale (rad; Hz "
                  "for the frequency); missing ones take the defaults",
                  "properties": {a: number("rad (Hz for frequency)", 0.0, math.pi) for a in ACTION_NAMES}},
        "every": {"type": "integer", "minimum": 1, "maximum": MAX_EVERY, "description": "time steps between two runs "
                  "of the network"},
        "omega_c_rad_s": number("rad/s: how fast the kinematics follow a command", maximum=MAX_OMEGA_C,
                                exclusive_minimum=0.0),
        "inputs": {"enum": list(INPUTS), "description": "the network's speeds over the ground or through the air"},
        "animal": {"enum": list(ANIMALS), "description": "the butterfly it flies (module "
                   "lifelike_mj.butterfly.flight3d.animals); missing: the paper's swallowtail"},
        "force_law": {"enum": list(FORCE_LAWS_FLOWN), "description": "the wing-force law it was evolved "
                      "with and flies with (module lifelike_mj.butterfly.flight3d.model); missing: exact"},
        "speed_gain_per_s": number("1/s: how fast the speed asked that the network sees rises while the ground speed "
                                   "falls short (0: never)", 0.0, MAX_SPEED_GAIN),
        "speed_boost_max_m_s": number("m/s: the most the speed asked is raised by", 0.0, MAX_BOOST_M_S),
        "provenance": {"type": "object"},
        "modes": {"type": "object", "additionalProperties": False, "description": "behaviour networks of the flight "
                  "network's shape: land flies a landing's last from_m (m), take_off the first for_s (s) of a take-off",
                  "properties": {m: {"type": "object", "additionalProperties": False, "required": ["weights"],
                                     "properties": {"weights": {"type": "array", "maxItems": max_weights,
                                                                "items": number("", -MAX_WEIGHT, MAX_WEIGHT)},
                                                    r: number("m" if m == "land" else "s", maximum=MAX_REACH,
                                                              exclusive_minimum=0.0)}}
                                 for m, r in MODES.items()}},
    }
    return document_schema(FORMAT, "lifelike-mj 3D butterfly controller", props, ["layers", "weights"],
                           "A network from the 3D butterfly's attitude and motion to changes of its wing and abdomen "
                           "kinematics, with the base command and the actions' scales.")


def _check_shapes(d: dict, schema: dict, where: str) -> dict:
    """Before a controller's numbers are checked one by one (:func:`controller_from_dict`): the lengths of its lists
    (:func:`~lifelike_mj.schema.too_long`: a list too long is refused by its length alone), then its ``layers``.
    Returns the document with each network's weights cut to one more than the layers need, whose numbers are then
    checked before their count (:func:`_check_count`): a bad number is named as before, and the work never grows
    beyond the network's shape."""
    from lifelike_mj.schema import too_long, validate

    too_long(d, schema, where)
    if "layers" not in d:
        return d  # the full check names what is missing
    validate({"layers": d["layers"]}, {"type": "object", "properties": {"layers": schema["properties"]["layers"]}},
             where)
    n = n_weights(_check_layers(d["layers"], where)) + 1
    cut = dict(d)
    if isinstance(d.get("weights"), list):
        cut["weights"] = d["weights"][:n]
    if isinstance(d.get("modes"), dict):
        cut["modes"] = {m: ({**spec, "weights": spec["weights"][:n]} if isinstance(spec, dict)
                            and isinstance(spec.get("weights"), list) else spec) for m, spec in d["modes"].items()}
    return cut


def controller_from_dict(data: object, name: str = "") -> Controller3D:
    """A :class:`Controller3D` from plain data (a parsed controller file); one sentence for anything wrong
    (checked against :func:`json_schema` before any value is used: first the lengths of its lists, then its layers,
    then the numbers of as many weights as the layers need and one more, then their count: the work never grows
    beyond the network's shape). A file of ``"kind": "designed"`` is one sentence saying where it flies
    (:func:`~lifelike_mj.butterfly.flight3d.designed.load_any` reads either kind)."""
    from lifelike_mj.butterfly.flight3d.kinematics import KinematicsCommand
    from lifelike_mj.errors import UserError
    from lifelike_mj.schema import check_header, validate

    where = f"3D controller {name}" if name else "3D controller"
    d = check_header(data, FORMAT, f"file {name}" if name else "the data", kind="3D controller file")
    kind = d.get("kind", "network")
    if kind == "designed":
        raise UserError(f"{where} is a designed controller (kind \"designed\"): it flies through 'lifelike-mj "
                        "butterfly fly3d' (assess3d, measure3d, strobe3d, land3d, garden) and Flight3D, not here, "
                        "where network controllers fly.")
    if kind != "network":
        raise UserError(f"{where}: kind is {' or '.join(repr(k) for k in KINDS)}, got {_short(kind)}.")
    schema = json_schema()
    validate(_check_shapes(d, schema, where), schema, where)
    layers = _check_layers(d["layers"], where)
    _check_count(where, layers, len(d["weights"]))
    for mode, spec in d.get("modes", {}).items():
        _check_count(where, layers, len(spec["weights"]), mode=mode)
    base = d.get("base")
    if base is not None:
        base = KinematicsCommand(**{k: float(v) for k, v in base.items()})
    return Controller3D(d["layers"], d["weights"], base, d.get("scale"), d.get("every", 1),
                        d.get("omega_c_rad_s", 2.0 * math.pi * 10.0), d.get("provenance"), name, d.get("inputs", "ground"),
                        d.get("animal", "swallowtail"), d.get("force_law", "exact"), d.get("modes"),
                        d.get("speed_gain_per_s", 0.0), d.get("speed_boost_max_m_s", 1.5))


#: Controllers once shipped and withdrawn, and why: on 100 random calm courses (``benchmarks/courses_3d.py``) each
#: rolled or pitched past 90 deg at least once, which no shipped controller may. The files of ``steer`` and ``wind``
#: are kept in the repository (:data:`WITHDRAWN_DIR`), loadable by path.
WITHDRAWN = {
    "cruise": "it fell on 31 and tumbled on 33 of 100 random calm courses",
    "steer": "it tumbled (rolled or pitched past 90 degrees) on 62 of 100 random calm courses",
    "wind": "it tumbled on 1 of 100 random calm courses",
}
#: Where the repository keeps the withdrawn controllers' files (relative to its root).
WITHDRAWN_DIR = "benchmarks/results/withdrawn"


def withdrawn_file(name: str):
    """The kept file (a :class:`~pathlib.Path`) of the withdrawn controller ``name`` (``steer`` or ``wind``), in a
    checkout of the repository (:data:`WITHDRAWN_DIR`; a wheel does not carry them): for benchmarks and tests that
    reproduce their numbers."""
    from lifelike_mj.errors import UserError, unknown_name
    from lifelike_mj.paths import controllers_dir

    if name not in WITHDRAWN:
        raise unknown_name("no withdrawn 3D controller", name, tuple(WITHDRAWN))
    path = controllers_dir().parent / WITHDRAWN_DIR / f"{name}.json"
    if not path.is_file():
        raise UserError(f"no withdrawn 3D controller file {name!r} here ({WITHDRAWN_DIR} is in a checkout of the "
                        "repository only).")
    return path


def read_controller_file(name_or_path) -> tuple[object, str]:
    """The parsed content and the name of a shipped 3D controller (by name, ``controllers/butterfly3d/``) or of any 3D
    controller file (by path), either kind. A withdrawn controller's name (:data:`WITHDRAWN`) gets a
    :class:`~lifelike_mj.errors.UserError` that says why; a file larger than :data:`MAX_FILE_BYTES` is refused by its
    size before it is read."""
    from pathlib import Path

    from lifelike_mj.errors import UserError
    from lifelike_mj.paths import read_json, resolve

    text = str(name_or_path)
    if text in WITHDRAWN and not Path(text).exists():
        kept = (f"its file is kept in the repository, {WITHDRAWN_DIR}/{text}.json (load it by path)"
                if text != "cruise" else "its file is in the repository's history")
        raise UserError(f"the 3D controller {text!r} was withdrawn: {WITHDRAWN[text]}; use 'monarch', or {kept}.")
    path = resolve("butterfly3d", name_or_path, "3D controller")
    return read_json(path, "3D controller", max_bytes=MAX_FILE_BYTES), path.stem


def load_controller(name_or_path) -> Controller3D:
    """A shipped 3D network controller by name (``controllers/butterfly3d/``) or any 3D controller file by path
    (:func:`read_controller_file`), its lists checked by their lengths before their numbers
    (:func:`controller_from_dict`)."""
    data, name = read_controller_file(name_or_path)
    return controller_from_dict(data, name)
