"""How the message area words an answer of the mission server (no Qt).

One sentence per answer, and its level: ``ok``, ``warning`` (accepted, but the operator
should know, e.g. queued for a robot out of contact) or ``error``.
"""

from __future__ import annotations

from .requests import Answer


def answer_message(answer: Answer, hint: str = "") -> tuple[str, str]:
    """The sentence for ``answer`` and its level; ``hint`` follows an accepted edit
    ("Ctrl+Z undoes it"). The revision is no word of an operator's: see :func:`answer_detail`."""
    what = answer.request.what or answer.request.operation.replace("_", " ")
    if answer.ok:
        suffix = f" ({hint})" if hint else ""
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


def answer_detail(answer: Answer) -> str:
    """What a roboticist may want of ``answer`` beyond its sentence: ``revision 626`` ("" if
    none); the message area keeps it in the message's tooltip."""
    revision = getattr(answer.value, "revision", None) if answer.ok else None
    return f"mission revision {revision}" if revision is not None else ""
