"""The calibrated wing-force law (issue 42, point 0): the filmed monarch's stroke at its filmed body angle flies as the
filmed monarch did (1.30 m/s forward, 0.38 m/s climb, Tejaswi et al. 2021's fit of a filmed flight), and the fit that
gives its two scales reproduces them."""

from lifelike_mj.butterfly.flight3d import calibrate
from lifelike_mj.butterfly.flight3d import model as mj3d

FILMED = calibrate.FILMED


def _within(got, want, tol=calibrate.TOLERANCE):
    return abs(got / want - 1.0) <= tol


def test_the_filmed_stroke_flies_the_filmed_speeds_with_the_calibrated_law_and_not_with_the_fruit_flys():
    cal = calibrate.filmed_flight()
    assert _within(cal["speed_m_s"], FILMED["speed_m_s"]) and _within(cal["climb_m_s"], FILMED["climb_m_s"])
    # the second measured quantity: the thorax bobs about 10 mm a beat (SD 3.4 mm over the filmed beats)
    assert abs(cal["bobbing_mm"] - FILMED["bobbing_mm"]) < 3.4
    # Dudley 1991: the downstroke carries the weight, the upstroke little or less than nothing
    assert 0.9 < cal["downstroke_weight_share"] < 1.3 and cal["upstroke_weight_share"] < 0.2
    plain = calibrate.filmed_flight(force_law="quasi_steady")
    assert not _within(plain["climb_m_s"], FILMED["climb_m_s"])  # the fruit fly's coefficients carry too much


def test_the_fit_from_another_start_finds_the_shipped_scales():
    got = calibrate.fit(start=(0.8, 0.3))
    k_l, k_d, k_rot = mj3d.CALIBRATED_QS
    assert abs(got["scales"][0] - k_l) < 0.02 and abs(got["scales"][1] - k_d) < 0.02 and k_rot == k_l
    assert _within(got["flight"]["speed_m_s"], FILMED["speed_m_s"], 0.02)
    assert _within(got["flight"]["climb_m_s"], FILMED["climb_m_s"], 0.02)
