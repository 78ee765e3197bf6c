"""The MPC's solver process: answers in order from a forked copy, errors passed back, ended
with its owner."""

from __future__ import annotations

import os
import threading

import pytest

from ridempc.errors import ConfigError, RidempcError
from ridempc.mpc.solver_process import SolverProcess, forks

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="needs fork (POSIX)")


class _Counter:
    """State the child copies at the fork and then keeps for itself."""

    def __init__(self) -> None:
        self.total = 0

    def add(self, value: int) -> tuple[int, int]:
        if value < 0:
            raise ConfigError(f"value {value} is negative")
        if value == 0:
            raise _Unsendable(lambda: None)
        self.total += value
        return self.total, os.getpid()


class _Unsendable(Exception):
    """An exception that cannot be pickled (it holds a lambda)."""

    def __init__(self, payload: object) -> None:
        super().__init__("unsendable")
        self.payload = payload


def test_each_item_is_worked_on_in_the_forked_copy_in_order() -> None:
    counter = _Counter()
    counter.total = 10  # copied at the fork, the first submit
    process = SolverProcess(counter.add)
    answers = [process.submit(v).result() for v in (1, 2, 3)]
    assert [total for total, _ in answers] == [11, 13, 16]
    assert {pid for _, pid in answers} != {os.getpid()} and len({p for _, p in answers}) == 1
    assert counter.total == 10  # the parent's own is untouched
    process.close()


def test_an_error_in_the_child_is_raised_in_the_parent_and_the_child_goes_on() -> None:
    process = SolverProcess(_Counter().add)
    with pytest.raises(ConfigError, match="value -1 is negative"):
        process.submit(-1).result()
    with pytest.raises(RidempcError, match="_Unsendable: unsendable"):
        process.submit(0).result()
    assert process.submit(5).result()[0] == 5
    process.close()


def test_close_ends_the_child_and_a_dead_child_is_an_error() -> None:
    process = SolverProcess(_Counter().add)
    _, pid = process.submit(1).result()
    process.close()
    with pytest.raises(ProcessLookupError):
        os.kill(pid, 0)  # reaped
    process = SolverProcess(_Counter().add)
    _, pid = process.submit(1).result()
    os.kill(pid, 9)
    with pytest.raises(RidempcError, match="solver process ended"):
        process.submit(1).result()


def test_no_fork_off_the_main_thread() -> None:
    seen: list[bool] = []
    thread = threading.Thread(target=lambda: seen.append(forks()))
    thread.start()
    thread.join()
    assert forks() and seen == [False]
