"""Stroboscopic pictures of one wing beat (flight3d.strobe, butterfly strobe3d)."""

import math

import numpy as np
import pytest

from lifelike_mj.butterfly.flight3d.controllers import default_base
from lifelike_mj.butterfly.flight3d.flight import Flight3D
from lifelike_mj.butterfly.flight3d.strobe import strobe


def _orange(img):
    r, g, b = (img[..., k].astype(int) for k in range(3))
    return (r > 150) & (g > 60) & (g < 170) & (b < 80)


def test_a_strobe_draws_the_beat_from_the_side_and_from_ahead(gl_backend):
    """Eight moments of the monarch's beat (body held): each view shows more wing than one moment does, the front
    view's wings spread over the whole stroke (wider and taller than at any one moment)."""
    f = Flight3D(default_base("monarch"), animal="monarch", assist="hold", pitch_law=lambda _f: math.radians(20.0))
    f.step(100)
    one = strobe(f, 2, ("front",), 320, 240)  # two moments half a beat apart
    many = strobe(f, 8, ("side", "front"), 320, 240)
    assert many.shape == (240, 640, 3) and one.shape == (240, 320, 3)
    front = _orange(many[:, 320:])
    assert front.sum() > 1.3 * _orange(one).sum() > 0
    rows = np.nonzero(front.any(axis=1))[0]
    assert np.ptp(rows) > 0.3 * 240  # the wings from the top of the stroke to its bottom
    assert _orange(many[:, :320]).sum() > 0


def test_a_strobe_names_bad_views():
    from lifelike_mj.errors import UserError

    f = Flight3D(default_base("monarch"), animal="monarch")
    with pytest.raises(UserError, match="unknown view 'back'"):
        strobe(f, 4, ("back",))


def test_a_take_off_is_drawn_as_it_leaves_the_flower(gl_backend):
    """The take-off picture (landing_strobe without a landing): the perched butterfly and its first moments in the air
    in one panel; more orange (wing) than one butterfly alone, spread sideways along its path. A landing that does
    not happen is one sentence."""
    from lifelike_mj.butterfly.flight3d.strobe import landing_strobe
    from lifelike_mj.errors import UserError

    flowers = ((0.0, 0.0, -0.1), (1.2, 0.4, -0.25))
    img, what = landing_strobe("monarch", flowers, land=False, every_s=0.04, after_s=0.3, width=320, height=240)
    assert img.shape == (240, 320, 3) and not what["landed"] and not what["drew_landing"]
    wings = _orange(img)
    cols = np.nonzero(wings.any(axis=0))[0]
    assert wings.sum() > 0 and np.ptp(cols) > 0.3 * 320
    with pytest.raises(UserError, match="did not land"):
        landing_strobe("monarch", flowers, width=64, height=48)
