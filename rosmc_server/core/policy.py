"""What a robot does when it loses contact with the ground station: its lost-link policy.

One typed policy for everyone: the operator's client and the CLI build it, the mission
server checks it against the library and sends it, the robot's executor applies it.

* ``continue`` (the default): keep executing.
* ``hold``: after ``after`` seconds without the ground, pause.
* ``safe_skill``: after ``after`` seconds, pause and run ``skill`` with ``params`` (say,
  ``return_to_lander``), then hold.

On the robot link the policy travels as JSON in a SET_OPTIONS command's argument,
``{"lost_link": {"policy": "hold", "after": 30.0, "skill": "", "params": {}}}``
(:func:`options_argument`, :func:`policy_from_argument`); :meth:`LostLinkPolicy.to_dict`
and :meth:`LostLinkPolicy.from_dict` give the inner object (the executor's state file
keeps it too).
"""

from __future__ import annotations

import enum
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from .errors import InvalidRequest
from .library import Library
from .params import Pose, check_json_data, value_to_data
from .validation import finite_float

DEFAULT_AFTER = 60.0
"""Seconds without the ground before a policy acts, unless the operator says otherwise."""


class LostLinkKind(enum.StrEnum):
    """What the robot does once the link has been silent for ``after`` seconds."""

    CONTINUE = "continue"
    HOLD = "hold"
    SAFE_SKILL = "safe_skill"

    @classmethod
    def parse(cls, text: str) -> LostLinkKind:
        """The kind named ``text`` (InvalidRequest naming the choices otherwise)."""
        try:
            return cls(text)
        except ValueError:
            choices = ", ".join(kind.value for kind in cls)
            raise InvalidRequest(
                f"the lost-link policy must be one of {choices}, got {text!r}"
            ) from None


@dataclass(frozen=True)
class LostLinkPolicy:
    """A robot's lost-link policy; checked on construction (InvalidRequest if malformed).

    Attributes:
        kind: continue, hold or run a safe skill.
        after: Seconds without hearing the ground before the policy acts (positive).
        skill: The safe skill (``safe_skill`` only; empty otherwise).
        params: The safe skill's parameter values as plain JSON data (a :class:`Pose` given
            is kept as its mapping); the robot reads them per the skill's schema.
    """

    kind: LostLinkKind = LostLinkKind.CONTINUE
    after: float = DEFAULT_AFTER
    skill: str = ""
    params: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        # The fields are checked as objects: the policy may come from JSON or a request.
        kind: object = self.kind
        if not isinstance(kind, LostLinkKind):
            object.__setattr__(self, "kind", LostLinkKind.parse(str(kind)))
        after = finite_float(self.after)
        if after is None or after <= 0:
            raise InvalidRequest("lost-link 'after' must be a positive number of seconds")
        object.__setattr__(self, "after", after)
        skill: object = self.skill
        if not isinstance(skill, str):
            raise InvalidRequest("the lost-link safe skill must be a skill name")
        params: object = self.params
        if not isinstance(params, Mapping):
            raise InvalidRequest("lost-link 'params' must be an object")
        data = {name: value_to_data(v) if isinstance(v, Pose) else v for name, v in params.items()}
        object.__setattr__(self, "params", check_json_data(data, "the safe skill's parameters"))
        if self.kind is LostLinkKind.SAFE_SKILL and not self.skill:
            raise InvalidRequest("a safe_skill lost-link policy names its safe skill")
        if self.kind is not LostLinkKind.SAFE_SKILL and (self.skill or self.params):
            raise InvalidRequest(
                f"a {self.kind.value} lost-link policy runs no safe skill (give safe_skill)"
            )

    def describe(self) -> str:
        """One line for operators, e.g. ``on link loss: hold after 30 s``."""
        if self.kind is LostLinkKind.CONTINUE:
            return "on link loss: continue"
        if self.kind is LostLinkKind.HOLD:
            return f"on link loss: hold after {self.after:g} s"
        return f"on link loss: run {self.skill} after {self.after:g} s, then hold"

    def to_dict(self) -> dict[str, Any]:
        """The policy as plain data: ``{"policy", "after", "skill", "params"}``."""
        return {
            "policy": self.kind.value,
            "after": self.after,
            "skill": self.skill,
            "params": dict(self.params),
        }

    def checked(self, library: Library, agent: str) -> LostLinkPolicy:
        """This policy with its safe skill checked against ``agent``'s skills in ``library``.

        The parameters are checked per the skill's schema; those not given take the
        library default. A policy without a safe skill is returned as it is.

        Raises:
            NotFound: ``agent`` has no such skill, or the skill no such parameter.
            InvalidRequest: A parameter value does not fit its schema.
        """
        if self.kind is not LostLinkKind.SAFE_SKILL:
            return self
        spec = library.skill(agent, self.skill)
        values = spec.defaults()
        values.update(
            {n: spec.parameter(n).check(raw, spec.name) for n, raw in self.params.items()}
        )
        params = {name: value_to_data(value) for name, value in values.items()}
        return LostLinkPolicy(self.kind, self.after, spec.name, params)

    @classmethod
    def from_dict(cls, data: object) -> LostLinkPolicy:
        """The policy of :meth:`to_dict`'s data; absent keys take the defaults.

        Raises:
            InvalidRequest: ``data`` is not such an object, or the policy it holds is not valid.
        """
        if not isinstance(data, Mapping):
            raise InvalidRequest("a lost-link policy must be an object")
        unknown = set(data) - {"policy", "after", "skill", "params"}
        if unknown:
            raise InvalidRequest(f"a lost-link policy has no field {sorted(unknown)[0]!r}")
        kind = data.get("policy", LostLinkKind.CONTINUE.value)
        if not isinstance(kind, str):
            raise InvalidRequest("the lost-link policy must be given by name")
        return cls(
            LostLinkKind.parse(kind),
            data.get("after", DEFAULT_AFTER),
            data.get("skill", ""),
            data.get("params", {}),
        )


def options_argument(policy: LostLinkPolicy) -> str:
    """The argument of the SET_OPTIONS robot command that sets ``policy``."""
    return json.dumps({"lost_link": policy.to_dict()}, separators=(",", ":"))


def policy_from_argument(text: str) -> LostLinkPolicy:
    """The policy a SET_OPTIONS argument sets (an empty argument: the default policy).

    Raises:
        InvalidRequest: The argument is not valid JSON, has no ``lost_link`` object, or
            the policy is not valid.
    """
    try:
        data = json.loads(text) if text.strip() else {}
    except (ValueError, RecursionError):
        raise InvalidRequest("the executor options are not valid JSON") from None
    if not isinstance(data, dict) or not isinstance(data.get("lost_link", {}), dict):
        raise InvalidRequest("the executor options must be an object with a 'lost_link' object")
    return LostLinkPolicy.from_dict(data.get("lost_link", {}))
