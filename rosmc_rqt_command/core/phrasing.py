"""How the message area words an answer of the mission server (no Qt).

One sentence per answer, and its level: ``ok``, ``warning`` (accepted, but the operator
should know, e.g. queued for a robot out of contact) or ``error``.
"""

from __future__ import annotations

from .requests import Answer


def answer_message(answer: Answer, hint: str = "") -> tuple[str, str]:
    """The sentence for ``answer`` and its level; ``hint`` follows an accepted edit's
    revision ("Ctrl+Z undoes it")."""
    what = answer.request.what or answer.request.operation.replace("_", " ")
    if answer.ok:
        revision = getattr(answer.value, "revision", None)
        extra = f"; {hint}" if hint else ""
        suffix = f" (revision {revision}{extra})" if revision is not None else ""
        note = getattr(answer.value, "note", "")
        if note:  # accepted, but the operator should know (queued, a barrier partner)
            return f"Done: {what}{suffix}; {note}.", "warning"
        return f"Done: {what}{suffix}.", "ok"
    if answer.conflict:
        return (
            f"Could not {what}: someone else changed the mission first ({answer.error}). "
            "The view was refreshed; check it and try again.",
            "error",
        )
    if answer.unreachable:
        return f"Could not {what}: the mission server did not answer ({answer.error}).", "error"
    return f"Could not {what}: {answer.error}.", "error"
