"""Plain YAML documents built straight from the parser's events, without a node tree.

PyYAML's loaders compose the whole document as a tree of nodes, two position marks each,
before they construct any value: for a mission file of 20,000 skills in block style that
tree is some 80 MiB, several times the data it becomes, and most of the time a load takes.
:func:`load_plain` reads the parser's events one at a time and builds the data as they
come, so only the data itself is ever held.

It reads only what plain data is made of: mappings with scalar keys, sequences,
scalars resolved as the safe loader resolves them (text, whole and decimal numbers,
booleans, null), and aliases of values complete before them (shared, as PyYAML shares
them; ``yaml.safe_dump`` writes repeated values so). Anything else (tags, merge keys,
timestamps, keys that are collections, a key given twice, an alias inside its own
anchor, more than one document, a syntax error) makes it answer that the text is not
plain, and the caller loads it with PyYAML as before, which reads it, or raises its usual
error, exactly as it always did.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import yaml
from yaml.events import (
    AliasEvent,
    DocumentEndEvent,
    DocumentStartEvent,
    MappingEndEvent,
    MappingStartEvent,
    ScalarEvent,
    SequenceEndEvent,
    SequenceStartEvent,
    StreamEndEvent,
)
from yaml.nodes import ScalarNode

_STR = "tag:yaml.org,2002:str"
_NULL = "tag:yaml.org,2002:null"
_BOOL = "tag:yaml.org,2002:bool"
_INT = "tag:yaml.org,2002:int"
_FLOAT = "tag:yaml.org,2002:float"
_NO_KEY = object()  # a mapping waiting for its next key
_OPEN = (dict, list)  # collections: not a key


class _NotPlain(Exception):
    """The text holds more than plain data (or is not valid YAML): load it the usual way."""


def load_plain(text: str, loader: type[yaml.SafeLoader]) -> tuple[bool, Any, bool]:
    """``(True, data, aliased)`` if ``text`` is one document of plain data, else
    ``(False, None, False)``; ``aliased`` says whether the text uses aliases.

    ``data`` equals what ``yaml.load(text, Loader=loader)`` returns for such a text (a
    test compares both on many documents); ``loader`` gives the implicit resolvers and
    the constructors of numbers and booleans.
    """
    parser = loader(text)
    anchors: dict[str, Any] = {}
    try:
        data = _build(parser, anchors)
    except (_NotPlain, yaml.YAMLError):
        return False, None, False
    finally:
        parser.dispose()
    return True, data, bool(anchors)


def _name(anchors: dict[str, Any], anchor: str, value: Any) -> None:
    """Remember the value of an anchor (one named twice is refused by the loader)."""
    if anchor in anchors:
        raise _NotPlain
    anchors[anchor] = value


def _build(parser: yaml.SafeLoader, anchors: dict[str, Any]) -> Any:
    """The document's data, event by event (raises _NotPlain for anything but plain data);
    ``anchors`` collects the values named by anchors."""
    get: Callable[[], Any] = parser.get_event  # untyped in the stubs
    get()  # the stream's start
    event = get()
    if type(event) is StreamEndEvent:
        return None  # an empty stream: yaml.load gives None
    if type(event) is not DocumentStartEvent:
        raise _NotPlain
    scalar = _scalar_reader(parser)
    root: list[Any] = []
    top: Any = root  # the collection being filled
    key: Any = _NO_KEY  # in a mapping, the key waiting for its value
    is_map = False
    stack: list[tuple[Any, bool, str | None]] = []
    while True:
        event = get()
        kind = type(event)
        if kind is ScalarEvent or kind is AliasEvent:
            if kind is AliasEvent:
                value = anchors.get(event.anchor, _NO_KEY)
                if value is _NO_KEY or (is_map and key is _NO_KEY and type(value) in _OPEN):
                    raise _NotPlain  # undefined, still open, or a collection as a key
            elif event.tag is not None:
                raise _NotPlain
            else:
                value = scalar(event.value) if event.implicit[0] else event.value
                if event.anchor is not None:
                    _name(anchors, event.anchor, value)
            if not is_map:
                top.append(value)
            elif key is _NO_KEY:
                if value in top:
                    raise _NotPlain  # a key given twice: the loader says where
                key = value
            else:
                top[key] = value
                key = _NO_KEY
        elif kind is MappingStartEvent or kind is SequenceStartEvent:
            if event.tag is not None:
                raise _NotPlain
            new: Any = {} if kind is MappingStartEvent else []
            if not is_map:
                top.append(new)
            elif key is _NO_KEY:
                raise _NotPlain  # a collection as a key
            else:
                top[key] = new
                key = _NO_KEY
            stack.append((top, is_map, event.anchor))
            top, is_map = new, kind is MappingStartEvent
        elif kind is MappingEndEvent or kind is SequenceEndEvent:
            done = top
            top, is_map, anchor = stack.pop()
            if anchor is not None:  # named once complete: an alias inside it is not plain
                _name(anchors, anchor, done)
        elif kind is DocumentEndEvent and not stack:
            break
        else:
            raise _NotPlain  # an alias, or what no plain document holds
    if type(get()) is not StreamEndEvent:
        raise _NotPlain  # a second document: the loader refuses it
    return root[0]


def _scalar_reader(parser: yaml.SafeLoader) -> Callable[[str], Any]:
    """A function giving the value of a plain (unquoted, untagged) scalar's text."""
    resolvers: dict[Any, list[tuple[str, Any]]] = parser.yaml_implicit_resolvers
    anywhere = resolvers.get(None, [])
    by_start = {start: found + anywhere for start, found in resolvers.items()}
    construct: dict[str, Callable[[ScalarNode], Any]] = {
        _NULL: parser.construct_yaml_null,
        _BOOL: parser.construct_yaml_bool,
        _INT: parser.construct_yaml_int,
        _FLOAT: parser.construct_yaml_float,
    }

    def value_of(text: str) -> Any:
        for tag, pattern in by_start.get(text[0] if text else "", anywhere):
            if pattern.match(text):
                make = construct.get(tag)
                if make is None:
                    raise _NotPlain  # a timestamp, a merge key, "=": what plain data is not
                return make(ScalarNode(tag, text))
        return text

    return value_of
