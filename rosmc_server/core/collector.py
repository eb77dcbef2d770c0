"""Pausing the cyclic garbage collector around work that makes many objects at once."""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Run the block without the cyclic collector (as it was before, afterwards).

    Loading a mission or giving a task a whole new order makes tens of thousands of
    objects at once, none in a cycle; with the collector on, they set off collections
    that walk far more than they made (at 25,000 skills per robot, more than half of a
    reorder's time in the core).
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
