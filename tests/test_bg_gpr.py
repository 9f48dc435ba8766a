"""The GPR basal ganglia of the bg controller (Girard et al. 2005, appendix A.1)."""

import numpy as np
import pytest

from agents.controllers.bg.gpr import (
    EP,
    BasalGanglia,
    LoopSpec,
    lateral_circular,
    select_dorsal,
    select_ventral,
)
from agents.controllers.bg.params import BgParams

THRESHOLD = 0.2
VENTRAL = BgParams().ventral_threshold  # the animat's: below 1.6 times the resting output


def lone_loop(channels: int = 6, feedback: float = 0.2) -> BasalGanglia:
    return BasalGanglia(LoopSpec(channels, feedback, circular=False), LoopSpec(0, 0.0, circular=True), cross=0.0)


def bump(centre: int, amplitude: float, n: int = 36, width: float = 1.5) -> np.ndarray:
    i = np.arange(n)
    d = np.minimum(np.abs(i - centre), n - np.abs(i - centre))
    return amplitude * np.exp(-0.5 * (d / width) ** 2)


def test_gurney_selection_protocol_with_the_incumbent_persisting():
    """Gurney et al. (2001b)'s protocol on 6 channels, one second per step."""
    bg = lone_loop()
    steps = [((0.0, 0.0), -1), ((0.4, 0.0), 0), ((0.4, 0.6), 1), ((0.6, 0.6), 1), ((0.4, 0.6), 1)]
    for (s1, s2), selected in steps:
        s = np.zeros(6)
        s[:2] = s1, s2
        bg.run(s, np.zeros(0), 1.0)
        d, _ = bg.disinhibition()
        assert select_dorsal(d, THRESHOLD) == selected, (s1, s2, d.round(2))
        if selected == 1:
            assert d[0] < 0.0  # channel 1 released from selection: inhibited beyond its resting level
    assert np.all(bg.disinhibition()[0][2:] < 0.0)  # channels without salience: more inhibited than at rest


def test_at_rest_nothing_is_selected_and_outputs_are_tonic():
    bg = lone_loop()
    bg.run(np.zeros(6), np.zeros(0), 1.0)
    y = bg.y_dorsal()
    assert np.allclose(y[EP], y[EP][0]) and 0.1 < y[EP][0] < 0.3  # tonic inhibition of every channel
    assert select_dorsal(bg.disinhibition()[0], THRESHOLD) == -1


def test_ventral_close_directions_give_a_compromise():
    bg = BasalGanglia()
    bg.run(np.zeros(2), np.maximum(bump(0, 0.5), bump(2, 0.5)), 1.0)
    direction, strength = select_ventral(bg.disinhibition()[1], VENTRAL)
    assert strength > 0 and abs(np.degrees(direction) - 10.0) < 1.0  # between 0 and 20 degrees


@pytest.mark.parametrize("other", [18, 9])
def test_ventral_distant_directions_give_a_choice(other):
    bg = BasalGanglia()
    bg.run(np.zeros(2), np.maximum(bump(0, 0.5), bump(other, 0.52)), 1.0)
    direction, strength = select_ventral(bg.disinhibition()[1], VENTRAL)
    assert strength > 0 and abs(np.degrees(direction) - 10.0 * other) < 1.0  # the stronger alone


def test_ventral_lateral_inhibition_grows_with_circular_distance():
    w = lateral_circular(36)
    assert w[0, 0] == 0 and w[0, 1] < w[0, 9] < w[0, 18] == 1.0
    assert w[0, 35] == w[0, 1]  # circular: 350 degrees is next to 0


def test_a_dorsal_selection_holds_the_ventral_loop_back():
    """The trans-subthalamic projection (eq. 10): a consummatory act raises every direction's EP/SNr
    output, so a direction the animat would take alone is no longer released."""
    from agents.controllers.bg.places import ANGLES
    from agents.controllers.bg.places import bump as von_mises

    directions = von_mises(ANGLES[5], 0.35, 4.0)  # an exploration-sized salience, as the animat's bumps are
    free, acting = BasalGanglia(), BasalGanglia()
    free.run(np.zeros(2), directions, 1.0)
    acting.run(np.array([0.6, 0.0]), directions, 1.0)
    assert select_ventral(free.disinhibition()[1], VENTRAL)[1] > 0
    d, v = acting.disinhibition()
    assert select_dorsal(d, THRESHOLD) == 0 and select_ventral(v, VENTRAL)[1] == 0.0
    assert acting.y_ventral()[EP].min() > 1.5 * free.y_ventral()[EP].min()


def test_euler_step_settles_at_one_millisecond_and_oscillates_at_two():
    """In the STN's linear range (a weak uniform salience) the diffuse projection makes
    explicit Euler stable only below dt = 1.5 ms at 36 channels (docs/bg.md)."""

    def change_per_step(dt: float) -> float:
        bg = BasalGanglia(dt=dt)
        bg.run(np.zeros(2), np.full(36, 0.1), 1.0)
        before = bg.a_v.copy()
        bg.run(np.zeros(2), np.full(36, 0.1), dt)
        return float(np.abs(bg.a_v - before).max())

    assert change_per_step(0.001) < 1e-6
    assert change_per_step(0.002) > 1e-3


def test_state_round_trip_is_bit_equal():
    a, b = BasalGanglia(), BasalGanglia()
    a.run(np.array([0.3, 0.1]), bump(7, 0.5), 0.3)
    b.restore(a.state())
    a.run(np.array([0.1, 0.5]), bump(20, 0.4), 0.3)
    b.run(np.array([0.1, 0.5]), bump(20, 0.4), 0.3)
    assert np.array_equal(a.a_v, b.a_v) and np.array_equal(a.a_d, b.a_d)
