"""What a robot does when it loses contact with the ground station: its lost-link policy.

One typed policy for everyone: the operator's client and the CLI build it, the mission
server checks it against the library and sends it, the robot's executor applies it.

* ``continue``: keep executing (and an idle robot out of coverage waits for ever).
* ``hold``: after ``after`` seconds without the ground, pause.
* ``safe_skill``: after ``after`` seconds, pause and run ``skill`` with ``params`` (say,
  ``return_to_lander``), then hold.
* ``return_to_link``: after ``after`` seconds, run ``skill`` (say, ``navigate_to``) with its
  one pose parameter set to where the robot last heard the ground, then hold.

After any kind but ``continue`` the robot holds until an operator resumes it; it reports so
(:class:`~..model.control.HoldCause`). There is deliberately no "resume on contact": a robot
that went on by itself once it heard the ground would follow the plan that took it out of
coverage, lose the link again and come back, over and over; the plan usually needs a change
first.

``when`` says which seconds count: ``silent`` (the robot has not heard the ground for
``after`` seconds, whatever it does) or ``idle`` (it has had nothing left to do *and* not
heard the ground for ``after`` seconds). The library declares a default per robot model
(:meth:`Library.default_policy`), which the server sends each robot when it first links.

On the robot link the policy travels as JSON in a SET_OPTIONS command's argument,
``{"lost_link": {"policy": "hold", "after": 30.0, "skill": "", "params": {},
"when": "silent"}}`` (with ``"default": true`` when it is the library's default)
(:func:`options_argument`, :func:`policy_from_argument`); :meth:`LostLinkPolicy.to_dict`
and :meth:`LostLinkPolicy.from_dict` give the inner object (the executor's state file
keeps it too).
"""

from __future__ import annotations

import enum
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from ..errors import InvalidRequest
from ..validation import finite_float
from .params import ParamType, Pose, Value, check_json_data, value_to_data


class ParameterSchema(Protocol):
    """What a policy's check needs of a skill parameter's schema (library.ParameterSpec)."""

    @property
    def name(self) -> str: ...
    @property
    def type(self) -> ParamType: ...
    def check(self, raw: object, skill: str) -> Value: ...


class SkillSchema(Protocol):
    """What a policy's check needs of a skill's schema (library.SkillSpec).

    Structural, so that the library (which reads each model's default policy) and
    this module do not import each other.
    """

    @property
    def name(self) -> str: ...
    @property
    def parameters(self) -> Sequence[ParameterSchema]: ...
    def parameter(self, name: str) -> ParameterSchema: ...
    def defaults(self) -> dict[str, Value]: ...


class SkillSource(Protocol):
    """Where a policy's skill is looked up (library.Library)."""

    def skill(self, agent: str, skill: str) -> SkillSchema: ...


DEFAULT_AFTER = 60.0
"""Seconds without the ground before a policy acts, unless the operator says otherwise."""

# A robot must hear the ground this many times within its policy's ``after`` for a healthy
# link never to look lost: one late beat on a loaded machine must not make the robot hold.
CONTACTS_PER_WINDOW = 4
LONGEST_CONTACT_PERIOD = 2.0
"""Seconds between the ground's beats to a robot with a long policy (or none)."""
SHORTEST_CONTACT_PERIOD = 0.25
"""The ground never beats faster: a policy of a second or less cannot be kept on a loaded link."""


def ground_contact_period(*afters: float | None) -> float:
    """Seconds between the ground's beats to a robot whose policy may act after ``afters``.

    ``afters`` are the silences after which the robot's policy acts, as the robot reported
    it and as the ground last asked (None: it never acts, or is not known); the shortest
    counts, since the robot may hold either until the ground hears which it took.
    """
    known = [after for after in afters if after is not None]
    if not known:
        return LONGEST_CONTACT_PERIOD
    period = min(known) / CONTACTS_PER_WINDOW
    return max(SHORTEST_CONTACT_PERIOD, min(LONGEST_CONTACT_PERIOD, period))


class LostLinkKind(enum.StrEnum):
    """What the robot does once the link has been silent for ``after`` seconds."""

    CONTINUE = "continue"
    HOLD = "hold"
    SAFE_SKILL = "safe_skill"
    RETURN_TO_LINK = "return_to_link"

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

    @property
    def runs_skill(self) -> bool:
        """Whether the policy runs a skill of its own (safe_skill, return_to_link)."""
        return self in (LostLinkKind.SAFE_SKILL, LostLinkKind.RETURN_TO_LINK)


class LostLinkTrigger(enum.StrEnum):
    """Which seconds count towards a policy's ``after``."""

    SILENT = "silent"
    """Seconds without the ground, whatever the robot does."""
    IDLE = "idle"
    """Seconds with nothing left to do and without the ground."""

    @classmethod
    def parse(cls, text: str) -> LostLinkTrigger:
        """The trigger named ``text`` (InvalidRequest naming the choices otherwise)."""
        try:
            return cls(text)
        except ValueError:
            raise InvalidRequest(
                f"the lost-link trigger must be silent or idle, got {text!r}"
            ) from None


@dataclass(frozen=True)
class LostLinkPolicy:
    """A robot's lost-link policy; checked on construction (InvalidRequest if malformed).

    Attributes:
        kind: continue, hold or run a safe skill.
        after: Seconds without hearing the ground before the policy acts (positive).
        skill: The safe skill (``safe_skill``), or the skill that goes to a pose
            (``return_to_link``); empty otherwise.
        params: The skill's parameter values as plain JSON data (a :class:`Pose` given
            is kept as its mapping); the robot reads them per the skill's schema.
        when: Which seconds count towards ``after``: silent (the default) or idle.
    """

    kind: LostLinkKind = LostLinkKind.CONTINUE
    after: float = DEFAULT_AFTER
    skill: str = ""
    params: Mapping[str, Any] = field(default_factory=dict)
    when: LostLinkTrigger = LostLinkTrigger.SILENT

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
        when: object = self.when
        if not isinstance(when, LostLinkTrigger):
            object.__setattr__(self, "when", LostLinkTrigger.parse(str(when)))
        if self.kind.runs_skill and not self.skill:
            raise InvalidRequest(f"a {self.kind.value} lost-link policy names its safe skill")
        if not self.kind.runs_skill and (self.skill or self.params):
            raise InvalidRequest(
                f"a {self.kind.value} lost-link policy runs no safe skill (give safe_skill)"
            )

    @property
    def acts_after(self) -> float | None:
        """Seconds of silence after which the policy acts (None: continue never acts)."""
        return None if self.kind is LostLinkKind.CONTINUE else self.after

    def describe(self) -> str:
        """One line for operators, e.g. ``on link loss: hold after 30 s``."""
        if self.kind is LostLinkKind.CONTINUE:
            return "on link loss: continue"
        wait = (
            f"after {self.after:g} s idle without a link"
            if self.when is LostLinkTrigger.IDLE
            else f"after {self.after:g} s"
        )
        if self.kind is LostLinkKind.HOLD:
            return f"on link loss: hold {wait}"
        if self.kind is LostLinkKind.RETURN_TO_LINK:
            where = f"the last link position ({self.skill})"
            return f"on link loss: return to {where} {wait}, then hold"
        return f"on link loss: run {self.skill} {wait}, then hold"

    def taken_as(self, in_force: LostLinkPolicy) -> bool:
        """Whether a robot reporting ``in_force`` took this policy (as sent, unchecked).

        The server completes a policy before sending it (:meth:`checked`): the safe skill's
        parameters not given take the library's defaults, so only those given must agree.
        """
        same = (self.kind, self.after, self.skill, self.when) == (
            in_force.kind,
            in_force.after,
            in_force.skill,
            in_force.when,
        )
        given = in_force.params
        return same and all(name in given and given[name] == v for name, v in self.params.items())

    def leaves_robot_out(self) -> bool:
        """Whether an idle robot out of coverage stays there under this policy."""
        return self.kind in (LostLinkKind.CONTINUE, LostLinkKind.HOLD)

    def to_dict(self) -> dict[str, Any]:
        """The policy as plain data: ``{"policy", "after", "skill", "params"[, "when"]}``.

        ``when`` is left out while it is ``silent``: executors from before idle triggers
        refuse a field they do not know, and read the policy as it always was.
        """
        data: dict[str, Any] = {
            "policy": self.kind.value,
            "after": self.after,
            "skill": self.skill,
            "params": dict(self.params),
        }
        if self.when is not LostLinkTrigger.SILENT:
            data["when"] = self.when.value
        return data

    def checked(self, library: SkillSource, agent: str) -> LostLinkPolicy:
        """This policy with its safe skill checked against ``agent``'s skills in ``library``.

        The parameters are checked per the skill's schema; those not given take the
        library default (but for ``return_to_link``'s pose parameter: the robot fills it
        in). A policy without a skill is returned as it is.

        Raises:
            NotFound: ``agent`` has no such skill, or the skill no such parameter.
            InvalidRequest: A parameter value does not fit its schema, or a return skill
                has not exactly one pose parameter.
        """
        if not self.kind.runs_skill:
            return self
        return self.checked_against(library.skill(agent, self.skill))

    def checked_against(self, spec: SkillSchema) -> LostLinkPolicy:
        """This policy with its skill's parameters checked against ``spec`` (see checked)."""
        values = spec.defaults()
        values.update(
            {n: spec.parameter(n).check(raw, spec.name) for n, raw in self.params.items()}
        )
        if self.kind is LostLinkKind.RETURN_TO_LINK:
            poses = [p.name for p in spec.parameters if p.type is ParamType.POSE]
            if len(poses) != 1:
                raise InvalidRequest(
                    f"the return skill {spec.name!r} must take exactly one pose parameter"
                )
            values.pop(poses[0])
        params = {name: value_to_data(value) for name, value in values.items()}
        return LostLinkPolicy(self.kind, self.after, spec.name, params, self.when)

    @classmethod
    def from_dict(cls, data: object) -> LostLinkPolicy:
        """The policy of :meth:`to_dict`'s data; absent keys take the defaults.

        Raises:
            InvalidRequest: ``data`` is not such an object, or the policy it holds is not valid.
        """
        if not isinstance(data, Mapping):
            raise InvalidRequest("a lost-link policy must be an object")
        unknown = set(data) - {"policy", "after", "skill", "params", "when"}
        if unknown:
            raise InvalidRequest(f"a lost-link policy has no field {sorted(unknown)[0]!r}")
        return cls(
            LostLinkKind.parse(_name(data.get("policy", "continue"), "policy")),
            data.get("after", DEFAULT_AFTER),
            data.get("skill", ""),
            data.get("params", {}),
            LostLinkTrigger.parse(_name(data.get("when", "silent"), "trigger")),
        )


@dataclass(frozen=True)
class PolicyInForce:
    """The lost-link policy a robot reports in force, and what it did.

    Attributes:
        policy: The policy the robot applies.
        library_default: Whether it is the library's default (no operator chose one).
        acted: What the policy did last, for operators ("" until it acted), e.g.
            ``held after 31 s without ground contact``.
    """

    policy: LostLinkPolicy = field(default_factory=LostLinkPolicy)
    library_default: bool = False
    acted: str = ""

    def describe(self) -> str:
        """One line for operators: the policy's words, whether it is the default, what it did."""
        text = self.policy.describe() + (" (library default)" if self.library_default else "")
        return text + (f"; {self.acted}" if self.acted else "")


def _name(value: object, what: str) -> str:
    if not isinstance(value, str):
        raise InvalidRequest(f"the lost-link {what} must be given by name")
    return value


def options_argument(policy: LostLinkPolicy, default: bool = False) -> str:
    """The argument of the SET_OPTIONS robot command that sets ``policy``.

    ``default``: the policy is the library's default, which a robot takes only while no
    operator has chosen its policy.
    """
    data: dict[str, Any] = {"lost_link": policy.to_dict()}
    if default:
        data["default"] = True
    return json.dumps(data, separators=(",", ":"))


def options_from_argument(text: str) -> tuple[LostLinkPolicy, bool]:
    """The policy a SET_OPTIONS argument sets, and whether it is the library's default.

    An empty argument sets the plain ``continue`` policy.

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
    default = data.get("default", False)
    if not isinstance(default, bool):
        raise InvalidRequest("the executor options' 'default' must be true or false")
    return LostLinkPolicy.from_dict(data.get("lost_link", {})), default


def policy_from_argument(text: str) -> LostLinkPolicy:
    """The policy a SET_OPTIONS argument sets (see :func:`options_from_argument`)."""
    return options_from_argument(text)[0]
