"""``rosmc_command``: the standalone window, imported without what its first paint does not need.

The window's first rows wait for every module imported before ``main()`` runs (issue 23:
process start to 10,000 rows painted, wanted within 1 s). Most of what the window offers
later is imported when first used (the replay bar and recordings, see
:mod:`.qt.replay_mode`); the one cost no module of ours controls is numpy, which
``genpy`` imports only to accept numpy scalars in messages (its ``import numpy`` is
optional). The window never puts numpy values in a message, and numpy's import (with its
BLAS threads) cost 60-250 ms on the 2-core machine, so the window's modules are imported
here while numpy is hidden; numpy itself stays importable for whoever needs it later (a
module of the window that imported numpy unconditionally would fail to start, which the
start-up test would show).
"""

from __future__ import annotations

import contextlib
import importlib
import sys
from collections.abc import Iterator, Sequence
from typing import cast

# What genpy would import although the window never uses it (see the module's docstring).
SKIPPED_BY_GENPY = "numpy"


@contextlib.contextmanager
def hidden(module: str) -> Iterator[None]:
    """Make ``import module`` fail inside the block (unless it was imported already).

    An optional import (``try: import numpy except ImportError``) then takes its fallback;
    after the block the module imports as usual.
    """
    if module in sys.modules:
        yield
        return
    sys.modules[module] = None  # type: ignore[assignment]  # what makes import raise
    try:
        yield
    finally:
        if sys.modules.get(module, 0) is None:
            del sys.modules[module]


def main(argv: Sequence[str] | None = None) -> int:
    """Open the command window (:func:`rosmc_rqt_command.standalone.main`)."""
    with hidden(SKIPPED_BY_GENPY):
        standalone = importlib.import_module("rosmc_rqt_command.standalone")
    return cast(int, standalone.main(argv))
