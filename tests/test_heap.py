"""The timed loops' frozen heap: what is alive before the loop is out of the collector's
walks during it, and handed back after, also when the loop raises."""

from __future__ import annotations

import gc

import pytest

from ridempc.heap import frozen_heap


def test_the_heap_is_frozen_inside_the_block_and_thawed_after() -> None:
    before = gc.get_freeze_count()
    alive = [[k] for k in range(1000)]  # tracked containers, alive before the loop
    with frozen_heap():
        assert gc.get_freeze_count() >= before + len(alive)
        made = [[k] for k in range(10)]
        assert all(gc.is_tracked(m) for m in made)  # new objects are collected as usual
    assert gc.get_freeze_count() == 0


def test_the_heap_is_thawed_when_the_loop_raises() -> None:
    with pytest.raises(RuntimeError), frozen_heap():
        raise RuntimeError("a diverged ride")
    assert gc.get_freeze_count() == 0
