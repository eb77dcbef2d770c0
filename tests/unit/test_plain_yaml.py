"""Plain YAML built from the parser's events reads exactly what PyYAML's safe loader reads.

:func:`~rosmc_server.core.documents.plain_yaml.load_plain` must be invisible: for any plain
document (random data written by ``yaml.safe_dump`` in every style, shared values as
aliases, every implicit scalar form of YAML 1.1) it gives the loader's data, value for
value and type for type; for anything else it declines, and ``load_yaml`` then gives the
loader's data or error as before. And it holds only the data: a block-style mission
document is read without the node tree PyYAML composes first.
"""

from __future__ import annotations

import math
import tracemalloc
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from rosmc_server.core.documents.documents import (
    _UniqueKeyLoader,
    load_yaml,
    read_yaml,
    yaml_problem,
)
from rosmc_server.core.documents.plain_yaml import load_plain


def typed(data: Any) -> Any:
    """``data`` with each value's type beside it (``1 == 1.0 == True`` in Python)."""
    if isinstance(data, dict):
        return ("map", [(typed(k), typed(v)) for k, v in data.items()])
    if isinstance(data, list):
        return ("seq", [typed(v) for v in data])
    if isinstance(data, float) and math.isnan(data):
        return ("float", "nan")
    return (type(data).__name__, data)


def loader_reads(text: str) -> Any:
    return yaml.load(text, Loader=_UniqueKeyLoader)


def plain_reads(text: str) -> Any:
    plain, data, _ = load_plain(text, _UniqueKeyLoader)
    assert plain, text
    return data


scalars = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**70), max_value=2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(max_size=12)
    | st.sampled_from(["yes", "No", "on", "~", "null", "0x1F", "017", "1:30", ".inf", "1e5", ""])
)
keys = st.none() | st.booleans() | st.integers(-5, 5) | st.text(max_size=8)
plain_data = st.recursive(
    scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(keys, inner, max_size=4),
    max_leaves=30,
)


@settings(max_examples=300, deadline=None)
@given(plain_data, st.sampled_from([None, True, False]), st.booleans())
def test_random_plain_data_reads_as_the_loader_reads_it(
    data: Any, flow: bool | None, shared: bool
) -> None:
    value = [data, data] if shared else data  # safe_dump writes a shared value as an alias
    text = yaml.safe_dump(value, default_flow_style=flow, allow_unicode=True)
    assert typed(plain_reads(text)) == typed(loader_reads(text))


IMPLICIT = """
- [yes, Yes, YES, no, No, NO, true, True, TRUE, false, on, On, ON, off, Off, OFF, y, n]
- [~, null, Null, NULL, '', "", '~', "null"]
- [0, -0, +12, 0x1F, 0x_1f, 0o17, 017, 0b101, 0b1_01, 1_000, 190:20:30, -1:30, 12a]
- [1.5, -.5, 1., 1e5, 1.5e+3, 6.8523015e+5, 685.230_15e+03, 190:20:30.15, .inf, -.Inf, +.INF]
- [.nan, .NaN, .NAN, 1.2.3, 0x1G, "1.5", '0x1F', 3e, e3]
- {1: a, 1.5: b, false: c, ~: d, x y: e, "quoted key": f, '': g}
- text with: colon and # no comment
- |
  a literal
  block
- >
  a folded
  block
- plain
  multi line
"""


def test_every_implicit_scalar_form_reads_as_the_loader_reads_it() -> None:
    assert typed(plain_reads(IMPLICIT)) == typed(loader_reads(IMPLICIT))
    assert plain_reads(IMPLICIT)[2][3] == 31 and plain_reads(IMPLICIT)[2][6] == 15  # YAML 1.1


@pytest.mark.parametrize(
    "text", ["", "# only a comment\n", "just text", "42", "[]", "{}", "---\na: 1\n...\n"]
)
def test_small_documents_read_as_the_loader_reads_them(text: str) -> None:
    assert typed(plain_reads(text)) == typed(loader_reads(text))


def test_aliases_of_complete_values_are_shared_as_the_loader_shares_them() -> None:
    text = "a: &p {x: 1}\nb: *p\nc: &s text\nd: [*s, *p]\n*s : key by alias\n"
    plain, data, aliased = load_plain(text, _UniqueKeyLoader)
    assert plain and aliased
    assert data == loader_reads(text)
    assert data["a"] is data["b"] is data["d"][1]
    assert not load_plain("a: {x: 1}\n", _UniqueKeyLoader)[2]  # no alias: nothing to expand


NOT_PLAIN = [
    "a: !!str 1\n",  # a tag
    "a: !custom 1\n",
    "!!python/object:os.system x\n",
    "base: &b {x: 1}\nc:\n  <<: *b\n  y: 2\n",  # a merge key
    "when: 2001-12-14\n",  # a timestamp
    "a: =\n",  # the value tag
    "? [a, b]\n: c\n",  # a collection as a key
    "a: &x [1, *x]\n",  # an alias inside its own anchor
    "a: *nowhere\n",  # an undefined alias
    "a: &x 1\nb: &x 2\n",  # an anchor named twice
    "a: 1\na: 2\n",  # a key given twice
    "a: 1\n---\nb: 2\n",  # two documents
    "a: [1, 2\n",  # a syntax error
    "a: 1\n b: 2\n",
]


@pytest.mark.parametrize("text", NOT_PLAIN)
def test_anything_but_plain_data_is_declined_and_loaded_as_before(text: str) -> None:
    assert load_plain(text, _UniqueKeyLoader) == (False, None, False)
    try:
        expected: Any = ("data", repr(loader_reads(text)))  # repr: one value is recursive
    except yaml.YAMLError as error:
        expected = ("error", type(error), yaml_problem(error))
    try:
        got: Any = ("data", repr(load_yaml(text)))
    except yaml.YAMLError as error:
        got = ("error", type(error), yaml_problem(error))
    assert got == expected


def test_a_duplicate_key_is_still_named_with_its_line() -> None:
    with pytest.raises(yaml.YAMLError) as raised:
        load_yaml("tasks:\n  a: 1\n  b: 2\n  a: 3\n")
    assert yaml_problem(raised.value) == "duplicate key 'a' at line 4"


def test_a_block_style_document_is_read_without_a_node_tree() -> None:
    skill = {"id": "", "skill": "move", "label": "step", "status": "IDLE"}
    entries = [
        dict(skill, id=f"r-{k:05d}", params={"target": {"x": k / 7, "y": 2.0}, "speed": 0.8})
        for k in range(3000)
    ]
    text = yaml.safe_dump({"rosmc_mission": 1, "tasks": {"robot": entries}}, sort_keys=False)
    tracemalloc.start()
    try:
        data, aliased = read_yaml(text)
        held, _ = tracemalloc.get_traced_memory()
        tracemalloc.reset_peak()
        del data
        data, _ = read_yaml(text)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert data["tasks"]["robot"] == entries and not aliased
    # The data itself, and little beside it (PyYAML's node tree was about six times it).
    assert peak < 2 * held, (peak, held)
