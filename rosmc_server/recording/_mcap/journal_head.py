"""The head of a journal file: its MCAP magic and header, intact or damaged.

A journal's magic and header are always the same bytes, so a damaged one is recognised for
what it was (:func:`damaged_journal_head`) and costs nothing but itself; a header that is
merely cut short or has a wrong length field is read as far as it goes
(:func:`read_journal_header`). Split from :mod:`.scan`, which starts every walk here.
"""

from __future__ import annotations

from pathlib import Path

from mcap.opcode import Opcode

from rosmc_server.recording._mcap import records as fmt
from rosmc_server.recording.channels import LIBRARY, PROFILE
from rosmc_server.recording.damage import Damage
from rosmc_server.recording.errors import JournalError

_HEAD = fmt.RECORD_HEAD.size
_JOURNAL_HEAD = fmt.MAGIC + fmt.header(PROFILE, LIBRARY)
"""The bytes every journal file starts with."""


def damaged_journal_head(path: Path, data: bytes) -> Damage | None:
    """The damage of a journal whose magic or header has a few wrong bytes (or is zeroed),
    None if its head is intact or it is not a journal at all.

    A journal's head is always the same bytes, so a damaged one is known for what it was
    and costs nothing but itself: the records after it are read as usual.
    """
    head = data[: len(_JOURNAL_HEAD)]
    if len(head) < len(_JOURNAL_HEAD) or head == _JOURNAL_HEAD:
        return None
    pairs = enumerate(zip(head, _JOURNAL_HEAD, strict=True))
    wrong = [i for i, (have, want) in pairs if have != want]
    if len(wrong) > len(_JOURNAL_HEAD) // 4 and head.strip(b"\0"):
        return None  # another file, not a damaged journal
    return Damage(path, wrong[0], len(_JOURNAL_HEAD), "a damaged MCAP magic or header", kept=True)


def read_journal_header(path: Path, data: bytes) -> tuple[str, str, int, list[Damage]]:
    """The header's profile and library, where the records after it start, and its damage."""
    head = fmt.record_head(data, len(fmt.MAGIC))
    if head is None:
        raise JournalError(
            f"journal {path} holds only {len(data)} bytes: it was cut short before its MCAP "
            "header was complete, so it holds no records"
        )
    if head[0] != Opcode.HEADER:
        raise JournalError(f"{path} is not a valid MCAP file (its first record is not a header)")
    declared = len(fmt.MAGIC) + _HEAD + head[1]
    try:
        profile, library, end = fmt.read_header(data, len(fmt.MAGIC) + _HEAD)
    except fmt.FormatError as err:
        if declared > len(data):
            return read_journal_header(path, data[: len(fmt.MAGIC) + 1])  # cut short: says so
        raise JournalError(
            f"{path} is not a valid MCAP file (its header is damaged: {err})"
        ) from err
    if end == declared or library != LIBRARY:
        return profile, library, declared, []
    # A journal's header ends where its two strings end, whatever its length field says.
    where = len(fmt.MAGIC) + 1
    return profile, library, end, [Damage(path, where, where + 8, "a damaged length field", True)]
