"""Turn ``key=value`` words of the command line into typed parameter values and bindings.

Values are read per the skill's library schema with :func:`core.params.parse_text`
(``altitude=12``, ``target=3,4,0,0,0,1.57``, ``target='{x: 3, y: 4}'``,
``area='[{x: 0, y: 0}, ...]'``). ``key=@MARKER`` binds the parameter to a task
marker, ``key=@`` unbinds it (keeping its value) and ``key=@@text`` is the text
``@text``. Task marker positions use the same pose syntax.
"""

from __future__ import annotations

from collections.abc import Sequence

import yaml

from ..core import InvalidRequest, MarkerType, Pose, SkillSpec
from ..core.skills.params import ParamType, parse_text


def split_assignment(word: str) -> tuple[str, str]:
    """``key=value`` as ``(key, value)``; ValueError if there is no key."""
    key, equals, value = word.partition("=")
    if not equals or not key.strip():
        raise ValueError(f"expected key=value, got {word!r}")
    return key.strip(), value


def typed_values(
    spec: SkillSpec, words: Sequence[str]
) -> tuple[dict[str, object], dict[str, str | None]]:
    """Values and marker bindings for ``spec`` from ``key=value`` words.

    Raises:
        ValueError: a word is not ``key=value`` (a usage error).
        NotFound: the skill has no such parameter.
        InvalidRequest: a value cannot be read as the parameter's type, or a key repeats.
    """
    values: dict[str, object] = {}
    bindings: dict[str, str | None] = {}
    for word in words:
        key, text = split_assignment(word)
        param = spec.parameter(key)
        if key in values or key in bindings:
            raise InvalidRequest(f"parameter '{key}' is given twice")
        if text.startswith("@") and not text.startswith("@@"):
            bindings[key] = text[1:] or None
        else:
            text = text[1:] if text.startswith("@@") else text
            what = f"parameter '{key}' of skill '{spec.name}'"
            values[key] = parse_text(param.type, text, what)
    return values, bindings


def parse_pose(text: str, what: str) -> Pose:
    """A pose from ``x,y[,z[,roll,pitch,yaw]]`` or a YAML mapping like ``{x: 1, y: 2}``."""
    return Pose.from_any(parse_text(ParamType.POSE, text, what), what)


def parse_vertices(text: str, what: str) -> tuple[Pose, ...]:
    """Polygon vertices from ``x,y x,y x,y`` (or ``;`` between them) or a YAML list."""
    stripped = text.strip()
    if stripped.startswith("["):
        try:
            raw = yaml.safe_load(stripped)
        except yaml.YAMLError as error:
            raise InvalidRequest(f"{what}: {text!r} is not valid YAML or JSON") from error
        if not isinstance(raw, list):
            raise InvalidRequest(f"{what} must be a list of points")
        return tuple(Pose.from_any(v, f"vertex {i} of {what}") for i, v in enumerate(raw))
    parts = stripped.replace(";", " ").split()
    return tuple(parse_pose(part, f"vertex {i} of {what}") for i, part in enumerate(parts))


def marker_shape(marker_type: MarkerType, where: str, what: str) -> tuple[Pose, tuple[Pose, ...]]:
    """The pose and vertices of a marker of ``marker_type`` given as text."""
    if marker_type is MarkerType.AREA:
        vertices = parse_vertices(where, what)
        return Pose(), vertices
    return parse_pose(where, what), ()
