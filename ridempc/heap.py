"""Keep the garbage collector off the long-lived heap while a timed loop runs.

CPython's cyclic collector walks every tracked object of the oldest generation on each
full collection. A ride or a benchmark holds many long-lived objects (the models, the motion
library, the recorded problems a benchmark replays): walking them made a full collection
cost more than a whole-body QP tick, a spike that the benchmark's p99 then reported as the
controller's (Hovershoes velocity-steps, 200 recorded WBC ticks under callgrind: the
collector took 13 % of the instructions). :func:`frozen_heap` collects once, then moves
everything alive into the permanent generation (``gc.freeze``) for the loop; objects made
inside the loop are collected as usual, and the frozen ones are handed back after it.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["frozen_heap"]


@contextmanager
def frozen_heap() -> Iterator[None]:
    """Freeze the objects alive now for the duration of the block (module docstring)."""
    gc.collect()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()
