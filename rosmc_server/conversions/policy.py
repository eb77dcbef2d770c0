"""The lost-link policy <-> the fields of ``rosmc/SetLostLinkPolicy`` requests.

Part of :mod:`rosmc_server.conversions`, the one boundary between the ``rosmc``
messages and the core. The request names the policy's kind in ``lost_link_policy``
and carries the safe skill's parameters as ``rosmc/ParameterValue`` messages.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import rosmc.msg as wire

from ..core import InvalidRequest, LostLinkKind, LostLinkPolicy, LostLinkTrigger
from ..core.skills.policy import DEFAULT_AFTER
from .values import params_from_msgs


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
