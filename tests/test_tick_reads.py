"""The tick's fast reads give the numbers of the general ones to the bit: the reference's
states at a tick's one or two times (row by row in floats) against its array path, and the
motor driver's joints and actuators as slices where they are runs."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ridempc.mpc.controller import LinearMpc
from ridempc.mpc.reference import _interp_rows
from ridempc.sim.motors import _indexer


def _array_path(reference, times: np.ndarray) -> np.ndarray:
    """``states_at`` as it reads many times: one search for all, broadcast offsets."""
    states = _interp_rows(times, reference.times, reference.states)
    states += np.maximum(times - reference.times[-1], 0.0)[:, None] * reference.steady_rates
    if reference.settle_states is not None:
        states += reference._settled(times)[:, None] * reference.settle_states
    return states


@pytest.mark.parametrize("settled", [True, False])
def test_a_ticks_few_times_read_the_states_of_the_array_path(settled: bool) -> None:
    reference = LinearMpc.from_library("cyberdog2", "skateboard", "accelerate", 0.5).reference
    assert reference.settle_states is not None  # the skateboard's push-offs settle
    if not settled:
        reference = replace(reference, settle_states=None, settle_inputs=None, settle_time=0.0)
    rng = np.random.default_rng(7)
    end = float(reference.times[-1])
    # before the start, on and between the nodes, at the end and in the settle after it
    times = np.concatenate(
        [rng.uniform(-0.5, end + 2.0, 400), reference.times, [end, end + 1e-12, end + 5.0]]
    )
    for k in range(len(times) - 1):
        for picked in (times[k : k + 1], times[k : k + 2]):
            fast, general = reference.states_at(picked), _array_path(reference, picked)
            assert np.array_equal(fast.view(np.int64), general.view(np.int64)), picked


def test_runs_of_indices_become_slices_and_others_stay() -> None:
    assert _indexer(np.array([6, 7, 8, 9])) == slice(6, 10)
    scattered = _indexer(np.array([7, 8, 9, 14]))
    assert isinstance(scattered, np.ndarray) and scattered.tolist() == [7, 8, 9, 14]
    values = np.arange(20.0)
    assert np.array_equal(values[_indexer(np.arange(3, 8))], values[np.arange(3, 8)])
