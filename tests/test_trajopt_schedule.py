"""Contact schedules: the paper's 1.2 s push period, strides, and the mode sequence."""

from __future__ import annotations

import numpy as np
import pytest

from ridempc.errors import ConfigError
from ridempc.trajopt.schedule import Contact, ContactSchedule, Phase, push_schedule, strides_for


@pytest.mark.parametrize(("target", "strides"), [(0.3, 1), (0.5, 2), (0.7, 3), (1.0, 4)])
def test_strides_and_periods(target: float, strides: int) -> None:
    assert strides_for(target) == strides
    schedule = push_schedule(target, n_feet=4, pusher=2)
    modes = [p.mode for p in schedule.phases]
    assert modes[0] == "four-leg" and modes[-1] == "four-leg"
    assert modes.count("push") == strides
    assert modes[1] == "three-leg" and modes[-2] == "three-leg"
    # Each stride (swing then push) lasts the paper's 1.2 s.
    for i, phase in enumerate(schedule.phases):
        if phase.mode == "push":
            assert schedule.phases[i - 1].duration + phase.duration == pytest.approx(1.2)
    # Only the pushing foot ever leaves the deck.
    masks = schedule.contact_masks()
    others = [0, 1, 3]
    assert np.all(masks[Contact.BOARD][:, others] == 1.0)
    assert masks[Contact.GROUND][:, 2].sum() > 0
    assert np.allclose(masks[Contact.BOARD] + masks[Contact.GROUND] + masks[Contact.SWING], 1.0)
    assert schedule.n_intervals == round(schedule.duration / schedule.dt)


def test_pushes_get_shorter_as_the_board_speeds_up() -> None:
    pushes = [p.duration for p in push_schedule(1.0, 4, 2).phases if p.mode == "push"]
    assert pushes == sorted(pushes, reverse=True)
    assert min(pushes) >= 0.2 - 1e-9


def test_phase_durations_must_fit_the_grid() -> None:
    with pytest.raises(ConfigError, match="whole number"):
        ContactSchedule((Phase("four-leg", 0.33, (Contact.BOARD,) * 4),), dt=0.05)
    with pytest.raises(ConfigError, match="every foot"):
        ContactSchedule(
            (Phase("a", 0.1, (Contact.BOARD,) * 4), Phase("b", 0.1, (Contact.BOARD,) * 3)), 0.05
        )
