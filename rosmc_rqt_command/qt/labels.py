"""Labels that never widen the window: long text wraps (or is cut) inside the room given.

A ``QLabel`` asks its layout for at least its longest line (or, wrapped, its longest word,
which for a file name is the whole name). A warning that arrives mid-mission must never
push the window wider than the screen and the parameter panel off it, so every label whose
text comes from outside (warnings, robot states, file names) is made with :func:`never_widen`.
"""

from __future__ import annotations

from python_qt_binding.QtWidgets import QLabel, QSizePolicy

# Narrow enough for any panel; a label never asks for more than this by itself.
MIN_LABEL_WIDTH = 40


def never_widen(label: QLabel, wrap: bool = True) -> QLabel:
    """Make ``label`` take the width it is given, never ask for more (wrapping if ``wrap``)."""
    label.setWordWrap(wrap)
    policy = QSizePolicy(QSizePolicy.Ignored, QSizePolicy.Preferred)
    policy.setHeightForWidth(wrap)
    label.setSizePolicy(policy)
    label.setMinimumWidth(MIN_LABEL_WIDTH)
    return label
