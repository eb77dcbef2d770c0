"""The lost-link policy a robot reports in force, read back from its words.

The robot reports its policy as one line (:meth:`LostLinkPolicy.describe`, then "(library
default)" and what the policy did). The *Link loss…* dialog opens on the policy in force,
so :func:`policy_in_force` reads that line back into a typed policy. No Qt here.
"""

from __future__ import annotations

import re

from rosmc_server.core import LostLinkKind, LostLinkPolicy, LostLinkTrigger

# The words of LostLinkPolicy.describe() (rosmc_server/core/skills/policy.py), in order.
_DESCRIBED = re.compile(
    r"^on link loss: (?:"
    r"(?P<continue>continue)"
    r"|hold (?P<hold>)"
    r"|return to the last link position \((?P<back>[^)]+)\) "
    r"|run (?P<skill>\S+) "
    r")(?:after (?P<after>[0-9.e+]+) s(?P<idle> idle without a link)?)?"
)


def policy_in_force(text: str) -> LostLinkPolicy | None:
    """The policy a robot's policy line describes; None if the line is not one."""
    found = _DESCRIBED.match(text)
    if found is None:
        return None
    if found["continue"]:
        return LostLinkPolicy()
    if found["after"] is None:
        return None
    after = float(found["after"])
    when = LostLinkTrigger.IDLE if found["idle"] else LostLinkTrigger.SILENT
    if found["hold"] is not None:
        return LostLinkPolicy(LostLinkKind.HOLD, after, when=when)
    if found["back"] is not None:
        return LostLinkPolicy(LostLinkKind.RETURN_TO_LINK, after, found["back"], when=when)
    return LostLinkPolicy(LostLinkKind.SAFE_SKILL, after, found["skill"], when=when)
