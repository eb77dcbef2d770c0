"""Checked parameters shared by the skills of a mission document that give the same values.

Part of reading a mission file (:mod:`.mission_reader`). Skills of one kind often carry
the same parameters (the library's defaults, a speed used throughout), and checking the
parameters is most of the work per skill. :class:`SharedParams` answers a skill whose raw
parameters are exactly those of an earlier skill of the same library skill with the dict
checked then: the check is skipped and one dict serves both skills (skills are immutable,
so sharing it is safe).

"Exactly" is by :func:`marshal.dumps`, which writes every value with its type and floats
bit for bit: ``1``, ``1.0`` and ``true`` differ, and so do ``0.0`` and ``-0.0``, as the
check would tell them apart. Nothing is ever read back from those bytes.
"""

from __future__ import annotations

import marshal
from typing import Any

from ..skills.library import SkillSpec
from ..skills.params import Value
from .plain_skills import Params

_KEEP_MOST = 4096  # checked dicts kept per document (bounds the memory of the keys)
_TRIES = 64  # skills in a row with parameters not seen before, then the reader stops looking


class SharedParams:
    """``check(spec, raw)``, answering raw parameters seen before for ``spec`` with the
    checked dict of that time (see the module's docstring). One per document read."""

    def __init__(self, check: Params) -> None:
        self._check = check
        self._seen: dict[tuple[int, bytes], dict[str, Value]] = {}
        self._tries = _TRIES  # looking costs more than it saves when nothing repeats

    def __call__(self, spec: SkillSpec, raw: dict[Any, Any]) -> dict[str, Value] | None:
        """The checked parameters (None, or RosmcError, as ``check`` answers)."""
        if not self._tries:
            return self._check(spec, raw)
        try:  # version 2: no references between values, so equal bytes are equal values
            key = (id(spec), marshal.dumps(raw, 2))  # the library keeps its specs alive
        except ValueError:  # a value marshal does not write (a YAML timestamp): checked
            return self._check(spec, raw)
        found = self._seen.get(key)
        if found is not None:
            self._tries = _TRIES
            return found
        self._tries -= 1
        checked = self._check(spec, raw)
        if checked is not None and len(self._seen) < _KEEP_MOST:
            self._seen[key] = checked
        return checked
