"""The lost-link policy <-> ``rosmc/SetLostLinkPolicy`` requests and ``rosmc/LostLinkPolicy``.

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core. The request names the policy's kind in ``lost_link_policy``;
``rosmc/LostLinkPolicy`` (the policy a robot reports in force, in the executor's snapshot
and the server's agent state) numbers it, with kind ``UNSAID`` for "not said" (None in
the core). Both carry the safe skill's parameters as ``rosmc/ParameterValue`` messages.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import rosmc.msg as wire

from ..core import InvalidRequest, LostLinkKind, LostLinkPolicy, LostLinkTrigger, PolicyInForce
from ..core.skills.params import Value
from ..core.skills.policy import DEFAULT_AFTER
from .values import param_to_msg, params_from_msgs


def policy_to_request(
    policy: LostLinkPolicy, parameters: Sequence[wire.ParameterValue] = ()
) -> dict[str, Any]:
    """The request fields that set ``policy`` (``parameters``: the safe skill's, as messages)."""
    return {
        "lost_link_policy": policy.kind.value,
        "after": policy.after,
        "safe_skill": policy.skill,
        "safe_skill_parameters": list(parameters),
        "when": policy.when.value,
    }


def policy_from_request(request: Any) -> LostLinkPolicy:
    """The policy a ``rosmc/SetLostLinkPolicy`` request asks for.

    Omitted fields take the defaults: an empty kind is continue, an empty ``when`` silent,
    ``after`` 0 :data:`~rosmc_server.core.skills.policy.DEFAULT_AFTER` seconds.

    The safe skill's parameters come as given; :meth:`LostLinkPolicy.checked` checks
    them against the library.

    Raises:
        InvalidRequest: An unknown kind, a delay that is not positive, parameters bound
            to task markers or malformed, or a safe skill where the kind runs none.
    """
    kind = LostLinkKind.parse(request.lost_link_policy or LostLinkKind.CONTINUE.value)
    values, bindings = params_from_msgs(request.safe_skill_parameters)
    if bindings:
        raise InvalidRequest("safe-skill parameters cannot be bound to task markers")
    when = LostLinkTrigger.parse(request.when or LostLinkTrigger.SILENT.value)
    after = request.after or DEFAULT_AFTER
    return LostLinkPolicy(kind, after, request.safe_skill, values, when)


_KINDS: dict[int, LostLinkKind] = {
    wire.LostLinkPolicy.CONTINUE: LostLinkKind.CONTINUE,
    wire.LostLinkPolicy.HOLD: LostLinkKind.HOLD,
    wire.LostLinkPolicy.SAFE_SKILL: LostLinkKind.SAFE_SKILL,
    wire.LostLinkPolicy.RETURN_TO_LINK: LostLinkKind.RETURN_TO_LINK,
}
_TRIGGERS: dict[int, LostLinkTrigger] = {
    wire.LostLinkPolicy.WHEN_SILENT: LostLinkTrigger.SILENT,
    wire.LostLinkPolicy.WHEN_IDLE: LostLinkTrigger.IDLE,
}


def policy_in_force_to_msg(in_force: PolicyInForce | None) -> wire.LostLinkPolicy:
    """The policy in force as ``rosmc/LostLinkPolicy`` (None: kind ``UNSAID``)."""
    if in_force is None:
        return wire.LostLinkPolicy(kind=wire.LostLinkPolicy.UNSAID)
    policy = in_force.policy
    # Policy parameters are JSON data (a pose is kept as its mapping), so each is a Value.
    parameters: dict[str, Value] = dict(policy.params)
    return wire.LostLinkPolicy(
        kind=_number(_KINDS, policy.kind),
        after=policy.after,
        skill=policy.skill,
        parameters=[param_to_msg(name, value) for name, value in parameters.items()],
        when=_number(_TRIGGERS, policy.when),
        library_default=in_force.library_default,
        acted=in_force.acted,
    )


def policy_in_force_from_msg(msg: wire.LostLinkPolicy | None) -> PolicyInForce | None:
    """``rosmc/LostLinkPolicy`` as the policy in force; None when it is not said.

    Raises:
        InvalidRequest: An unknown kind or trigger number, or a policy that is not valid.
    """
    if msg is None or msg.kind == wire.LostLinkPolicy.UNSAID:
        return None
    kind = _KINDS.get(msg.kind)
    when = _TRIGGERS.get(msg.when)
    if kind is None or when is None:
        raise InvalidRequest(f"unknown lost-link policy numbers (kind {msg.kind}, when {msg.when})")
    values, bindings = params_from_msgs(msg.parameters)
    if bindings:
        raise InvalidRequest("safe-skill parameters cannot be bound to task markers")
    policy = LostLinkPolicy(kind, msg.after, msg.skill, values, when)
    return PolicyInForce(policy, msg.library_default, msg.acted)


def _number(numbers: Mapping[int, object], known: object) -> int:
    return next(number for number, value in numbers.items() if value is known)
