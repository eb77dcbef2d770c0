"""The checks every way into the mission shares: add, edit, load, robot reports.

A mission file, a robot report and an operator's request can all put text and numbers into
the mission. Whatever the way in, the same limits hold, so that what one path accepts
another never refuses later (a saved mission loads again) and nothing the mission holds can
flood a terminal or a log: text is one line, free of control characters (line breaks,
terminal escape codes) and of lone surrogates (not text: they cannot be sent or saved), and
short; ids are plain tokens; counts are bounded. The limits, in one place:

============================  =====================  =========================================
limit                         value                  refused when
============================  =====================  =========================================
``MAX_LABEL``                 120 characters         a skill label is longer
``MAX_NAME``                  80 characters          a task marker or barrier name is longer
``MAX_ID``                    64 characters          a skill id is longer
``MAX_STATUS_TEXT``           500 characters         (a robot's status text is cut, not refused)
``MAX_TEXT``                  4,096 characters       a string parameter value is longer
``MAX_PATH``                  1,024 characters       a mission file path is longer (or holds a
                                                     control character, a line break say)
``MAX_CORNERS``               1,000                  an area marker has more corners
``MAX_SKILLS``                50,000                 a mission would hold more skills
============================  =====================  =========================================

Each is checked before anything is parsed further, so a refusal takes milliseconds.

Errors quote offending input through :func:`excerpt`: short and escaped.
"""

from __future__ import annotations

import math
import re
import unicodedata

from .errors import InvalidRequest

MAX_LABEL = 120
MAX_NAME = 80  # task marker and barrier names
MAX_ID = 64
MAX_STATUS_TEXT = 500
MAX_RETRIES = 100
MAX_TEXT = 4096  # a string parameter value
MAX_PATH = 1024  # a mission file path
MAX_CORNERS = 1000  # corners of one area marker
MAX_SKILLS = 50_000  # skills of one mission (20 robots x 500 skills is 10,000)
MAX_ATTEMPT = 10_000
EXCERPT = 40

_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.:-]*")


def excerpt(value: object, limit: int = EXCERPT) -> str:
    """``value`` quoted for an error message: escaped (repr) and cut to about ``limit``."""
    text = repr(value) if not isinstance(value, str) else repr(value[: limit + 1])
    if isinstance(value, str) and len(value) > limit:
        return f"{repr(value[:limit])[:-1]}…{text[-1]} ({len(value)} characters)"
    return text if len(text) <= limit + 2 else f"{text[:limit]}…"


def has_control_characters(text: str) -> bool:
    """Whether ``text`` holds a line break, tab, escape or other control/format character."""
    if text.isprintable():  # no Cc or Cf (nor spaces other than ' '): the common case, in C
        return False
    return any(unicodedata.category(ch) in ("Cc", "Cf", "Cs") for ch in text)


def check_encodable(text: str, what: str) -> str:
    """``text`` if it is text (UTF-8 can encode it): a lone surrogate is refused."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError as error:
        raise InvalidRequest(
            f"{what} holds a lone surrogate {text[error.start]!a} at character "
            f"{error.start}, which is not text"
        ) from None
    return text


def check_text(value: str, what: str) -> str:
    """A string parameter value: text of at most MAX_TEXT characters."""
    if len(value) > MAX_TEXT:
        raise InvalidRequest(f"{what} holds at most {MAX_TEXT} characters, got {len(value)}")
    return check_encodable(value, what)


def check_corners(count: int, name: str) -> None:
    """Refuse an area of more than MAX_CORNERS corners (before reading any of them)."""
    if count > MAX_CORNERS:
        raise InvalidRequest(
            f"an area has at most {MAX_CORNERS} corners; marker {excerpt(name)} has {count}"
        )


def check_skill_count(count: int) -> None:
    """Refuse a mission of more than MAX_SKILLS skills."""
    if count > MAX_SKILLS:
        raise InvalidRequest(f"a mission holds at most {MAX_SKILLS} skills, this one {count}")


def check_file_path(path: str) -> str:
    """A mission file path: one line of at most MAX_PATH characters, no control character."""
    if not path or len(path) > MAX_PATH or has_control_characters(path):
        raise InvalidRequest(
            f"a mission file path must be one line of 1 to {MAX_PATH} printable characters, "
            f"got {excerpt(path)}"
        )
    return path


def check_one_line(text: object, what: str, max_length: int, *, empty: bool = False) -> str:
    """``text`` stripped, if it is one line of printable text of at most ``max_length``."""
    if not isinstance(text, str):
        raise InvalidRequest(f"{what} must be text, got {excerpt(text)}")
    stripped = text.strip()
    if not stripped and not empty:
        raise InvalidRequest(f"{what} must not be empty")
    if len(stripped) > max_length or has_control_characters(stripped):
        raise InvalidRequest(
            f"{what} must be one line of at most {max_length} printable characters, "
            f"got {excerpt(text)}"
        )
    return stripped


def check_id(value: object, what: str = "a skill id") -> str:
    """A plain token: letters, digits and ``_ . : -``, at most MAX_ID characters."""
    if not isinstance(value, str) or len(value) > MAX_ID or not _ID.fullmatch(value):
        raise InvalidRequest(
            f"{what} must be 1 to {MAX_ID} letters, digits, '_', '.', ':' or '-', "
            f"got {excerpt(value)}"
        )
    return value


def check_whole(value: object, what: str, minimum: int, maximum: int) -> int:
    """A whole number within ``minimum..maximum``."""
    if isinstance(value, bool) or not isinstance(value, int) or not minimum <= value <= maximum:
        raise InvalidRequest(
            f"{what} must be a whole number from {minimum} to {maximum}, got {excerpt(value)}"
        )
    return value


def finite_float(value: object) -> float | None:
    """``value`` as a float if it is a finite number (an int or float, not a bool), else None.

    An integer too large for a float (YAML reads ``1`` followed by 400 digits as one) is
    not a finite float either, rather than an OverflowError.
    """
    if type(value) is float:  # the common case first
        return value if math.isfinite(value) else None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        number = float(value)
    except OverflowError:
        return None
    return number if math.isfinite(number) else None


def check_time(value: object, what: str) -> float:
    """A finite, non-negative number of seconds."""
    number = finite_float(value)
    if number is None or number < 0:
        raise InvalidRequest(
            f"{what} must be a finite number of seconds >= 0, got {excerpt(value)}"
        )
    return number


def clip_status_text(text: str) -> str:
    """A robot's status text made safe to hold: control characters become spaces, cut short.

    Robots are not refused for a long or odd sentence (the report still counts); the
    mission keeps a clean excerpt of it.
    """
    cleaned = "".join(
        " " if unicodedata.category(ch) in ("Cc", "Cf") else ch
        for ch in text[: MAX_STATUS_TEXT * 2]
    ).strip()
    return cleaned if len(cleaned) <= MAX_STATUS_TEXT else cleaned[: MAX_STATUS_TEXT - 1] + "…"
