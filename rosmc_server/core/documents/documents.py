"""Reading parsed YAML documents (libraries, mission files, scenarios) with precise errors.

A :class:`DocumentReader` checks one piece of a document at a time and, on a
problem, raises the caller's error class with one sentence naming the source
file, the key path and the problem, e.g.
``library.yaml: models.drone.skills.take_off.duration: must not be negative``.
"""

from __future__ import annotations

import re
from typing import Any, NoReturn

import yaml

from ..errors import RosmcError
from ..validation import excerpt, finite_float
from .plain_yaml import load_plain

# libyaml's C loader and dumper when present: the same safe subset (plain data only,
# no Python object tags), several times faster on large missions.
SafeLoader: type[yaml.SafeLoader] = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
SafeDumper: type[yaml.SafeDumper] = getattr(yaml, "CSafeDumper", yaml.SafeDumper)


MAX_NESTING = 100  # deeper YAML is refused before parsing: libyaml can crash on it
_BRACKETS = re.compile(r"[\[\]{}]")
_INDENT = re.compile(r"^( *)", re.MULTILINE)


def load_yaml(text: str) -> Any:
    """Parse YAML text as plain data only (a Python object tag raises ConstructorError).

    A document nested more than MAX_NESTING levels deep raises YAMLError without
    being parsed: deep enough nesting crashes libyaml (and recursion limits Python's).
    """
    return read_yaml(text)[0]


def read_yaml(text: str) -> tuple[Any, bool]:
    """Parse YAML text as :func:`load_yaml` does; also say whether the data may share
    values through aliases (only then can it expand beyond the text).

    Plain data is built from the parser's events (see :mod:`.plain_yaml`), anything
    else by PyYAML's safe loader, as before.
    """
    depth = deepest = 0
    for match in _BRACKETS.finditer(text):
        depth += 1 if match.group() in "[{" else -1
        deepest = max(deepest, depth)
    indent = max((len(m.group(1)) for m in _INDENT.finditer(text)), default=0)
    if deepest > MAX_NESTING or indent > 2 * MAX_NESTING:
        raise yaml.YAMLError(f"the document is nested more than {MAX_NESTING} levels deep")
    plain, data, aliased = load_plain(text, _UniqueKeyLoader)
    if plain:
        return data, aliased
    return yaml.load(text, Loader=_UniqueKeyLoader), True  # nosec: a safe loader


class DuplicateKeyError(yaml.MarkedYAMLError):
    """A mapping names the same key twice (``problem`` names it, ``problem_mark`` the line)."""


def yaml_problem(error: yaml.YAMLError) -> str:
    """The problem of a YAML error and its line, on one line (str(error) spans several)."""
    problem = getattr(error, "problem", None) or str(error).splitlines()[0]
    mark = getattr(error, "problem_mark", None)
    return f"{problem} at line {mark.line + 1}" if mark is not None else str(problem)


class _UniqueKeyLoader(SafeLoader):  # type: ignore[misc,valid-type]
    """The safe loader, refusing a mapping that names a key twice ("last one wins" hides typos)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[object] = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue  # "<<" merges may repeat keys on purpose
            key = self.construct_object(key_node, deep=True)
            if isinstance(key, (str, int, float, bool)) or key is None:
                if key in seen:
                    raise DuplicateKeyError(
                        None, None, f"duplicate key {excerpt(key)}", key_node.start_mark
                    )
                seen.add(key)
        return dict(super().construct_mapping(node, deep=deep))


class DocumentReader:
    """Checks the pieces of one parsed document; failures raise ``error``."""

    def __init__(self, source: str, error: type[RosmcError]) -> None:
        self.source = source
        self.error = error

    def fail(self, key: str, problem: str) -> NoReturn:
        """Raise the reader's error about ``key``."""
        where = f"{self.source}: {key}" if key else self.source
        raise self.error(f"{where}: {problem}")

    def mapping(
        self,
        raw: object,
        key: str,
        required: set[str] | frozenset[str] = frozenset(),
        optional: set[str] | frozenset[str] | None = None,
        allow_none: bool = False,
    ) -> dict[str, Any]:
        """A mapping with text keys, the ``required`` ones, and (unless None) no keys
        beyond ``optional``."""
        if raw is None and allow_none:
            raw = {}
        if not isinstance(raw, dict):
            self.fail(key, f"must be a mapping, got {type(raw).__name__}")
        for name in raw:
            if not isinstance(name, str):
                self.fail(key, f"has a non-text key {excerpt(name)}")
        missing = sorted(required - raw.keys())
        if missing:
            self.fail(key, f"is missing {', '.join(missing)}")
        if optional is not None:
            unknown = sorted(raw.keys() - required - optional)
            if unknown:
                self.fail(key, f"has unknown keys {', '.join(unknown)}")
        return raw

    def items(self, raw: object, key: str) -> list[Any]:
        """A list."""
        if not isinstance(raw, list):
            self.fail(key, f"must be a list, got {type(raw).__name__}")
        return raw

    def text(self, raw: object, key: str, empty: bool = False) -> str:
        """Text, non-empty unless ``empty``."""
        if not isinstance(raw, str) or (not empty and not raw.strip()):
            self.fail(key, f"must be non-empty text, got {excerpt(raw)}")
        return raw

    def number(
        self, raw: object, key: str, minimum: float | None = None, maximum: float | None = None
    ) -> float:
        """A finite number within the bounds given."""
        if isinstance(raw, bool) or not isinstance(raw, (int, float)):
            self.fail(key, f"must be a number, got {excerpt(raw)}")
        number = finite_float(raw)
        if number is None:
            self.fail(key, f"must be a finite number, got {excerpt(raw)}")
        if minimum is not None and number < minimum:
            self.fail(key, f"must be at least {minimum:g}, got {excerpt(raw)}")
        if maximum is not None and number > maximum:
            self.fail(key, f"must be at most {maximum:g}, got {excerpt(raw)}")
        return number

    def positive(self, raw: object, key: str) -> float:
        """A finite number above zero."""
        value = self.number(raw, key)
        if value <= 0:
            self.fail(key, f"must be positive, got {excerpt(raw)}")
        return value

    def whole(self, raw: object, key: str, minimum: int) -> int:
        """A whole number of at least ``minimum``."""
        if isinstance(raw, bool) or not isinstance(raw, int) or raw < minimum:
            self.fail(key, f"must be a whole number >= {minimum}, got {excerpt(raw)}")
        return raw

    def enum(self, kind: Any, raw: object, key: str) -> Any:
        """A member of enum ``kind``, given by name."""
        names = [member.name for member in kind]
        if raw not in names:
            self.fail(key, f"must be one of {', '.join(names)}, got {excerpt(raw)}")
        return kind[raw]
