"""The neural pitch controller of Oe 2010 section 6.1 (eq. 12), compiled.

Network: 6 inputs -> 6 hidden neurons -> 1 output neuron, every neuron with the transfer function
``G(u) = 1/(1+exp(-12(u+0.5))) + 1/(1+exp(-12(u-0.5))) - 1`` (eq. 12, range (-1, 1), flat near 0).
The output is scaled to a pitch change of at most ``max_dphi`` (3 degrees) per integration step,
and the pitch is clipped to ``[-phi_limit, phi_limit]`` (30 degrees), as section 6.3 states.

The paper gives neither input scaling nor biases. Our choice (kept fixed in the controller file):

* inputs, in the paper's order, divided by a scale so that their usual range is about [-1, 1]:
  ``phi / 30 deg``, ``omega / (theta_a 2 pi f)`` (the flap's peak rate), ``(theta - theta_c) /
  theta_a`` (flap angle about the stroke centre), ``v_y / 2 m/s`` (climb rate), ``y / 10 m``
  (altitude above the target 0 m), ``v_z / 3 m/s`` (forward speed; 3 m/s as in eq. 13). The
  altitude and climb-rate scales span the experiments' range (start altitudes of +-10 m of
  section 7.1, sink rates up to about 2 m/s). In a trial (one seed, 300 generations) with 1 m and 1 m/s
  the network held level flight as well but crashed from +10 m (E7); with 10 m and 2 m/s two of
  two trial seeds descended from +10 m and held 0 m;
* one bias per neuron (hidden and output): 6 x (6 + 1) + 6 + 1 = 49 weights (genes);
* velocities are air-relative (``inputs = "relative"``) or ground velocities (``"ground"``),
  the two readings of section 7.2; without wind they are the same.

Weight order (the genome): for hidden neuron ``h = 0..5``: its 6 input weights then its bias
(indices ``7h .. 7h + 6``); then the 6 output weights (42..47) and the output bias (48).

Networks of other shapes (``layers``, e.g. ``[6, 8, 8, 1]``: six inputs, two hidden layers of eight,
one output; or ``[6, 1]``, the output neuron alone: a linear policy) use the same inputs, transfer
function, output scaling and weight order (per layer, per neuron: its input weights, then its bias),
and run in :func:`mlp_pitch`; the paper's ``[6, 6, 1]``
keeps its unrolled :func:`ann_pitch` (and :func:`mlp_pitch` computes the same numbers bit for bit).

Compiled code sees the controller as a float array (see ``A_*`` below); :func:`ann_pitch` and
:func:`mlp_pitch` are the step functions shared by the paper backend and the MuJoCo stepping loop.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

N_INPUTS = 6
N_HIDDEN = 6
N_WEIGHTS = N_HIDDEN * (N_INPUTS + 1) + N_HIDDEN + 1  # 49
#: The paper's network: 6 inputs, 6 hidden neurons, 1 output (section 6.1).
PAPER_LAYERS = (N_INPUTS, N_HIDDEN, 1)
#: Widest hidden layer and most hidden layers a network file may ask for.
MAX_WIDTH = 64
MAX_HIDDEN_LAYERS = 8
INPUT_NAMES = ("phi", "omega", "theta", "climb_rate", "altitude", "forward_speed")
INPUT_KINDS = ("relative", "ground")

# layout of the compiled parameter array
A_RELATIVE, A_DMAX, A_LIMIT, A_THETA_C = 0, 1, 2, 3
A_SCALE = 4  # 6 multipliers (1 / scale) in input order
A_W = A_SCALE + N_INPUTS  # 10: the 49 weights
N_COMPILED = A_W + N_WEIGHTS
# a network of any shape (mlp_pitch): A_W holds the number of layers L (inputs and output counted),
# then the L sizes, then the weights, then room for two layers of activations
A_NLAYERS = A_W

#: Default input scales (units in the key names); the theta and omega scales follow the flap.
DEFAULT_SCALES = {"phi_deg": 30.0, "vy_m_s": 2.0, "y_m": 10.0, "vz_m_s": 3.0}
DEFAULT_MAX_DPHI_DEG = 3.0
DEFAULT_PHI_LIMIT_DEG = 30.0


@njit(cache=True, inline="always", error_model="numpy")
def transfer(u):
    """``G(u)`` of Oe 2010 eq. 12 (dimensionless)."""
    return 1.0 / (1.0 + math.exp(-12.0 * (u + 0.5))) + 1.0 / (1.0 + math.exp(-12.0 * (u - 0.5))) - 1.0


@njit(cache=True, inline="always", error_model="numpy")
def scaled_inputs(cp, theta, omega, y, vy, vz, air_y, air_z, phi_prev):
    """The network's six inputs in the paper's order (module docstring), divided by their scales;
    velocities air-relative when the controller says so (section 7.2)."""
    if cp[A_RELATIVE] > 0.5:
        vy = vy - air_y
        vz = vz - air_z
    return (phi_prev * cp[A_SCALE], omega * cp[A_SCALE + 1], (theta - cp[A_THETA_C]) * cp[A_SCALE + 2],
            vy * cp[A_SCALE + 3], y * cp[A_SCALE + 4], vz * cp[A_SCALE + 5])


@njit(cache=True, inline="always", error_model="numpy")
def pitch_step(cp, phi_prev, out):
    """The new pitch (rad) from the output neuron's sum ``out``: a change of at most ``max_dphi``
    (``G(out)`` scaled), the pitch clipped to ``[-phi_limit, phi_limit]`` (section 6.3)."""
    phi = phi_prev + cp[A_DMAX] * transfer(out)
    lim = cp[A_LIMIT]
    if phi > lim:
        phi = lim
    elif phi < -lim:
        phi = -lim
    return phi


@njit(cache=True, inline="always", error_model="numpy")
def ann_pitch(cp, theta, omega, y, vy, vz, air_y, air_z, phi_prev):
    """New pitch (rad) from the previous pitch ``phi_prev`` (rad), flap angle ``theta`` (rad) and
    rate ``omega`` (rad/s), altitude ``y`` (m, relative to the start), ground velocities ``vy``
    (up), ``vz`` (forward) and the air velocity (m/s)."""
    x0, x1, x2, x3, x4, x5 = scaled_inputs(cp, theta, omega, y, vy, vz, air_y, air_z, phi_prev)
    out = cp[A_W + 48]
    for h in range(N_HIDDEN):
        b = A_W + 7 * h
        s = cp[b] * x0 + cp[b + 1] * x1 + cp[b + 2] * x2 + cp[b + 3] * x3 + cp[b + 4] * x4 + cp[b + 5] * x5 + cp[b + 6]
        out += cp[A_W + 42 + h] * transfer(s)
    return pitch_step(cp, phi_prev, out)


def default_scales(flap) -> dict:
    """The documented input scales for a :class:`~lifelike_mj.butterfly.params.FlapPattern`
    (see module docstring): omega over the flap's peak rate ``theta_a 2 pi f``, theta about its centre."""
    return {
        "phi_deg": DEFAULT_SCALES["phi_deg"],
        "omega_rad_s": float(flap.theta_a * 2.0 * math.pi * flap.frequency_hz),
        "theta_center_deg": math.degrees(flap.theta_c),
        "theta_half_range_deg": math.degrees(flap.theta_a),
        "vy_m_s": DEFAULT_SCALES["vy_m_s"],
        "y_m": DEFAULT_SCALES["y_m"],
        "vz_m_s": DEFAULT_SCALES["vz_m_s"],
    }


SCALE_KEYS = ("phi_deg", "omega_rad_s", "theta_center_deg", "theta_half_range_deg", "vy_m_s", "y_m", "vz_m_s")


def compile_params(inputs: str, scales: dict, weights, max_dphi_deg: float = DEFAULT_MAX_DPHI_DEG,
                   phi_limit_deg: float = DEFAULT_PHI_LIMIT_DEG) -> np.ndarray:
    """The compiled parameter array of one network (rad inside)."""
    cp = np.zeros(N_COMPILED)
    cp[A_RELATIVE] = 1.0 if inputs == "relative" else 0.0
    cp[A_DMAX] = math.radians(max_dphi_deg)
    cp[A_LIMIT] = math.radians(phi_limit_deg)
    cp[A_THETA_C] = math.radians(scales["theta_center_deg"])
    cp[A_SCALE : A_W] = (
        1.0 / math.radians(scales["phi_deg"]),
        1.0 / scales["omega_rad_s"],
        1.0 / math.radians(scales["theta_half_range_deg"]),
        1.0 / scales["vy_m_s"],
        1.0 / scales["y_m"],
        1.0 / scales["vz_m_s"],
    )
    cp[A_W:] = np.asarray(weights, dtype=float)
    return cp


def n_weights(layers) -> int:
    """Number of weights (genes) of a network with these layer sizes (biases included)."""
    return int(sum((a + 1) * b for a, b in zip(layers[:-1], layers[1:])))


def check_layers(layers) -> tuple[int, ...]:
    """``layers`` as a tuple if it is a valid network shape (6 inputs, 1 output, 0 to
    :data:`MAX_HIDDEN_LAYERS` hidden layers of 1 to :data:`MAX_WIDTH` neurons; ``[6, 1]`` is the output
    neuron alone, a linear policy passed through ``G``), else a ``ValueError``."""
    try:
        t = tuple(int(x) for x in layers)
        ok = all(float(x) == int(x) and not isinstance(x, bool) for x in layers)
    except (TypeError, ValueError):
        raise ValueError(f"layers must be a list of whole numbers, got {layers!r}") from None
    if not ok or len(t) < 2 or t[0] != N_INPUTS or t[-1] != 1:
        raise ValueError(f"layers must start with {N_INPUTS} (the inputs) and end with 1 (the output), "
                         f"got {list(layers)}")
    if len(t) - 2 > MAX_HIDDEN_LAYERS or not all(1 <= h <= MAX_WIDTH for h in t[1:-1]):
        raise ValueError(f"at most {MAX_HIDDEN_LAYERS} hidden layers of 1 to {MAX_WIDTH} neurons, got {list(t)}")
    return t


def compile_mlp(inputs: str, scales: dict, weights, layers, max_dphi_deg: float = DEFAULT_MAX_DPHI_DEG,
                phi_limit_deg: float = DEFAULT_PHI_LIMIT_DEG) -> np.ndarray:
    """The compiled parameter array of a network of any shape (:func:`mlp_pitch`; rad inside)."""
    layers = check_layers(layers)
    head = compile_params(inputs, scales, np.zeros(N_WEIGHTS), max_dphi_deg, phi_limit_deg)[:A_W]
    w = np.asarray(weights, dtype=float).ravel()
    if len(w) != n_weights(layers):
        raise ValueError(f"a {list(layers)} network has {n_weights(layers)} weights, got {len(w)}")
    scratch = np.zeros(2 * max(layers))
    return np.concatenate([head, [float(len(layers))], np.asarray(layers, dtype=float), w, scratch])


def weights_offset(layers) -> int:
    """Index of the first weight in the compiled array of a network with these layers."""
    return A_W if tuple(layers) == PAPER_LAYERS else A_NLAYERS + 1 + len(layers)


@njit(cache=True, inline="always", error_model="numpy")
def mlp_pitch(cp, theta, omega, y, vy, vz, air_y, air_z, phi_prev):
    """:func:`ann_pitch` for a network of any shape (compiled array of :func:`compile_mlp`): the same
    inputs and output scaling; hidden neurons ``G(sum_i w_i x_i + b)``, the output neuron
    ``b + sum_i w_i x_i`` passed through ``G`` as the pitch change (the sums in the order of
    :func:`ann_pitch`, so that a ``[6, 6, 1]`` network gives its numbers bit for bit). The
    activations are kept in the array's last ``2 * max(layers)`` entries."""
    nl = int(cp[A_NLAYERS])
    w0 = A_NLAYERS + 1 + nl
    width = 0
    for k in range(nl):
        width = max(width, int(cp[A_NLAYERS + 1 + k]))
    nw = 0
    for k in range(nl - 1):
        nw += (int(cp[A_NLAYERS + 1 + k]) + 1) * int(cp[A_NLAYERS + 2 + k])
    a = w0 + nw  # activations of the current layer's inputs
    b = a + width  # ... and its outputs
    x = scaled_inputs(cp, theta, omega, y, vy, vz, air_y, air_z, phi_prev)
    for i in range(N_INPUTS):
        cp[a + i] = x[i]
    w = w0
    out = 0.0
    for k in range(nl - 1):
        n_in = int(cp[A_NLAYERS + 1 + k])
        n_out = int(cp[A_NLAYERS + 2 + k])
        last = k == nl - 2
        for j in range(n_out):
            if last:
                s = cp[w + n_in]
                for i in range(n_in):
                    s += cp[w + i] * cp[a + i]
                out = s
            else:
                s = cp[w] * cp[a]
                for i in range(1, n_in):
                    s += cp[w + i] * cp[a + i]
                cp[b + j] = transfer(s + cp[w + n_in])
            w += n_in + 1
        a, b = b, a
    return pitch_step(cp, phi_prev, out)
