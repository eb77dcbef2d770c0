"""What a robot does when it loses contact with the ground station."""

from __future__ import annotations

import json
from collections.abc import Collection
from dataclasses import dataclass, field
from typing import Any

KINDS = ("continue", "hold", "safe_skill")


@dataclass(frozen=True)
class LostLinkPolicy:
    """``continue`` (default), ``hold`` after ``after`` seconds, or run ``skill`` then hold."""

    kind: str = "continue"
    after: float = 60.0
    skill: str = ""
    params: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def from_json(cls, text: str, skills: Collection[str]) -> LostLinkPolicy:
        """Parse ``{"lost_link": {"policy": ..., "after": s, "skill": ..., "params": {}}}``."""
        try:
            data = json.loads(text) if text.strip() else {}
        except ValueError:
            raise ValueError("the executor options are not valid JSON") from None
        if not isinstance(data, dict) or not isinstance(data.get("lost_link", {}), dict):
            raise ValueError("the executor options must be an object with a 'lost_link' object")
        body = data.get("lost_link", {})
        kind = body.get("policy", "continue")
        after = body.get("after", 60.0)
        skill = body.get("skill", "")
        params = body.get("params", {})
        if kind not in KINDS:
            raise ValueError(f"lost-link policy must be one of {', '.join(KINDS)}, got {kind!r}")
        if isinstance(after, bool) or not isinstance(after, (int, float)) or not after > 0:
            raise ValueError("lost-link 'after' must be a positive number of seconds")
        if kind == "safe_skill" and skill not in skills:
            raise ValueError(f"the safe skill {skill!r} is not implemented on this robot")
        if not isinstance(params, dict):
            raise ValueError("lost-link 'params' must be an object")
        return cls(kind, float(after), str(skill), params)

    def describe(self) -> str:
        """One line for operators."""
        if self.kind == "continue":
            return "on link loss: continue"
        if self.kind == "hold":
            return f"on link loss: hold after {self.after:g} s"
        return f"on link loss: run {self.skill} after {self.after:g} s, then hold"
