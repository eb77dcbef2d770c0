"""Mission documents written one line per skill read back exactly, by ROSMC and by any YAML.

The fast writer (:class:`MissionDumper`) and reader (:func:`read_document`) must be
invisible: a random mission of 10,000 skills, with every status, parameter type, marker
binding and the text and numbers on which JSON and YAML disagree, comes back identical
through ``parse_mission``, and libyaml reads the very same data from the file. Lines that
only look like the writer's (JSON that YAML reads otherwise, entries inside a block
scalar, guessed placeholders) are read exactly as YAML reads them.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import replace
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from rosmc_server.core import (
    Library,
    MissionFileError,
    dump_mission,
    parse_mission,
)
from rosmc_server.core.documents.documents import load_yaml, yaml_problem
from rosmc_server.core.files import document_reading, mission_text
from rosmc_server.core.files.document_reading import read_document
from rosmc_server.core.files.mission_text import (
    MissionDumper,
    digest_line,
    entry,
    flow_line,
    mission_to_dict,
)
from tests.unit.random_missions import TRICKY, random_content


def test_a_random_10000_skill_mission_round_trips_exactly(library: Library) -> None:
    content = random_content(library, 10_000)
    text = MissionDumper().dump(content, 42)
    assert parse_mission(text, library, "x") == (content, 42)
    assert dump_mission(*parse_mission(text, library, "x")) == text  # even -0.0 and 5e-324
    # Any YAML reader reads the same data: libyaml here, pure-Python PyYAML below.
    assert yaml.load(text, Loader=yaml.CSafeLoader) == mission_to_dict(content, 42)
    lines = text.splitlines()
    flow = sum(row.startswith("  - {") for row in lines)
    block = sum(row.startswith("  - id: ") for row in lines)
    # Most skills are one JSON line; the rest (text YAML would fold, 1e-05, a long key)
    # fall back to YAML's block style, and both kinds are in the file.
    assert flow > 8000 and block > 100, (flow, block)


def test_pure_python_yaml_reads_the_same(library: Library) -> None:
    content = random_content(library, 600, seed=3)
    text = dump_mission(content, 7)
    assert yaml.load(text, Loader=yaml.SafeLoader) == mission_to_dict(content, 7)


def test_saving_again_writes_only_the_changed_skills_afresh(
    library: Library, monkeypatch: pytest.MonkeyPatch
) -> None:
    content = random_content(library, 3000, seed=5)
    dumper = MissionDumper()
    first = dumper.dump(content, 1)
    written: list[str] = []
    real = mission_text.skill_to_dict

    def counting(skill: Any) -> dict[str, Any]:
        written.append(skill.id)
        return real(skill)

    monkeypatch.setattr(mission_text, "skill_to_dict", counting)
    second = dumper.dump(content, 2)
    assert body(second) == body(first).replace("revision: 1", "revision: 2", 1)
    assert written == []
    edited = content.copy()
    old = edited.tasks["bravo"][-1]
    edited.tasks["bravo"][-1] = replace(old, label="edited label")
    text = dumper.dump(edited, 3)
    assert written == [old.id]
    assert '"label": "edited label"' in text
    assert parse_mission(text, library, "x") == (edited, 3)


def body(document: str) -> str:
    """The document without its digest line (the last)."""
    text, digest = document[:-1].rsplit("\n", 1)
    assert digest.startswith("# sha256 of the text above: ")
    return text + "\n"


def test_a_document_ends_with_the_digest_of_its_text(library: Library) -> None:
    text = MissionDumper().dump(random_content(library, 50, seed=3), 7)
    assert text.endswith(digest_line(body(text)))
    assert hashlib.sha256(body(text).encode()).hexdigest() in text.splitlines()[-1]


def test_a_digested_document_is_read_without_checking_each_line(
    library: Library, monkeypatch: pytest.MonkeyPatch
) -> None:
    content = random_content(library, 300, seed=11)
    text = MissionDumper().dump(content, 4)

    def refuse(lines: list[str], items: list[dict[str, Any]]) -> bool:
        raise AssertionError("a digested document's lines are not checked again")

    monkeypatch.setattr(document_reading, "_written_alike", refuse)
    assert read_document(text, "x") == yaml.load(text, Loader=yaml.CSafeLoader)
    assert parse_mission(text, library, "x") == (content, 4)


@pytest.mark.parametrize(
    ("line", "edited"),
    [
        ('"speed": 0.5', '"speed": 5e-1'),  # JSON's float, YAML 1.1's text
        ('"label": "a"', '"label": "a\u0085"'),  # NEL: a line break to YAML
    ],
    ids=["exponent", "next-line"],
)
def test_an_edited_document_is_read_as_yaml_reads_it(line: str, edited: str) -> None:
    document = f'items:\n- {{{line}}}\n- {{"id": "b"}}\n'
    document += digest_line(document)
    assert read_document(document, "x") == yaml.load(document, Loader=yaml.CSafeLoader)
    changed = document.replace(line, edited)  # the digest is stale now
    assert read_document(changed, "x") == yaml.load(changed, Loader=yaml.CSafeLoader)


def test_a_matching_digest_over_lines_the_writer_never_writes_changes_nothing() -> None:
    # Two lines that are one JSON value, and one line holding two: as many values as
    # lines, but no line is one entry. YAML refuses the text; so must the reader.
    text = 'items:\n- {"a": [{}\n- {}]}\n- {"x": 1}, {"y": 2}\n'
    text += digest_line(text)
    with pytest.raises(yaml.YAMLError):
        yaml.load(text, Loader=yaml.CSafeLoader)
    with pytest.raises(yaml.YAMLError):
        read_document(text, "x")


TRICKY_TEXT = st.lists(st.sampled_from(TRICKY), max_size=5).map("".join) | st.text(max_size=6)


@settings(max_examples=300, deadline=None)
@given(
    st.dictionaries(
        TRICKY_TEXT,
        st.recursive(
            st.none()
            | st.booleans()
            | st.integers(-(2**70), 2**70)
            | st.floats(allow_nan=False, allow_infinity=False)
            | TRICKY_TEXT,
            lambda inner: (
                st.lists(inner, max_size=3) | st.dictionaries(TRICKY_TEXT, inner, max_size=3)
            ),
            max_leaves=12,
        ),
        max_size=4,
    )
)
def test_every_entry_reads_back_as_written(data: dict[str, Any]) -> None:
    document = "items:\n" + entry(data, "") + entry(data, "")
    assert yaml.load(document, Loader=yaml.CSafeLoader) == {"items": [data, data]}
    assert read_document(document, "x") == {"items": [data, data]}
    line = flow_line(data)
    if line is not None:  # JSON that YAML reads the same: no float without a fraction
        assert yaml.load(f"- {line}", Loader=yaml.SafeLoader) == [data]


LOOKALIKES = [
    '- {"a":1}',  # not as the writer spaces it
    '- {"a": 1e5}',  # JSON's float is YAML's text
    '- {"a": 1e-05}',
    '- {"a": NaN}',
    '- {"a": Infinity}',
    '- {"a": 1, "a": 2}',  # a duplicate key YAML refuses
    '- {"a": "\\ud83d\\ude00"}',  # a surrogate pair YAML keeps as two characters
    '- {"a": "\\/"}',
    '- {"a": 1} # a comment',
    '- {"a": 1}, {"b": 2}',  # two values on one line
    '- {"a": "x\u2028y"}',  # a line separator YAML folds
    '- {"a": "\u0085"}',
]


@pytest.mark.parametrize("row", LOOKALIKES)
def test_lines_that_only_look_like_the_writers_read_as_yaml_does(row: str) -> None:
    document = f'items:\n{row}\n- {{"b": 2.5}}\n'
    try:
        expected = load_yaml(document)
    except yaml.YAMLError as error:
        with pytest.raises(type(error)):
            read_document(document, "x")
        return
    assert read_document(document, "x") == expected


@pytest.mark.parametrize("row", ['- {"a": {"b": 1}\n  }', '- {"a": 1, "b": {}\n  , "c": 2}'])
def test_a_flow_mapping_ending_on_a_later_line_reads_as_yaml_does(row: str) -> None:
    # Each line is scanned where it stands in the text: a value must end at its line's end.
    document = f'items:\n{row}\n- {{"b": 2.5}}\n'
    for text in (document, document + digest_line(document)):
        assert read_document(text, "x") == load_yaml(text)


def test_flow_lines_inside_other_yaml_stay_what_yaml_makes_of_them() -> None:
    inner = '  - {"id": "a", "n": 1.5}\n'
    documents = [
        f"note: |\n{inner}  - done\nitems: []\n",  # inside a literal block
        f"note: 'x\n{inner}'\n",  # inside a single-quoted scalar over lines
        f"items: [\n{inner}]\n",  # inside a flow sequence: not YAML at all
        f"items:\n{inner}{inner}other:\n{inner}",  # a repeated run elsewhere
        f"a: &list\n{inner}b: *list\n",  # an alias to a run
    ]
    for document in documents:
        try:
            expected = load_yaml(document)
        except yaml.YAMLError:
            with pytest.raises(yaml.YAMLError):
                read_document(document, "x")
            continue
        assert read_document(document, "x") == expected, document


def test_a_guessed_placeholder_is_just_text(library: Library) -> None:
    content = random_content(library, 30, seed=9)
    text = dump_mission(content, 1)
    # Placeholder-shaped strings (the real token is random per read) stay strings.
    shaped = '"0123456789abcdef01234567:0"'
    spoofed = f'{text}note: {shaped}\nextra:\n- {shaped}\n- {{"a": 1.5}}\n'
    data = read_document(spoofed, "x")
    assert data == load_yaml(spoofed)
    assert data["extra"] == ["0123456789abcdef01234567:0", {"a": 1.5}]


def test_errors_name_the_documents_own_lines(library: Library) -> None:
    text = dump_mission(random_content(library, 30, seed=4), 1)
    rows = text.splitlines()
    broken = "\n".join([*rows[:6], '  - {"id": [unclosed', *rows[6:]]) + "\n"
    with pytest.raises(yaml.YAMLError) as plain:
        load_yaml(broken)
    with pytest.raises(MissionFileError) as caught:
        parse_mission(broken, library, "m.yaml")
    # The line YAML names in the whole document, not in the text it parsed quickly.
    assert str(caught.value) == f"m.yaml: not valid YAML ({yaml_problem(plain.value)})"
    assert "at line 8" in str(caught.value)


def test_a_bad_skill_among_quick_ones_is_named_precisely(library: Library) -> None:
    content = random_content(library, 90, seed=6)
    text = dump_mission(content, 1)
    rows = text.splitlines()
    row = next(i for i, row in enumerate(rows) if row.startswith('  - {"id": "bravo-'))
    data = json.loads(rows[row][4:])
    data["attempt"] = 0
    rows[row] = "  - " + json.dumps(data, ensure_ascii=False)
    with pytest.raises(MissionFileError) as caught:
        parse_mission("\n".join(rows) + "\n", library, "m.yaml")
    index = int(data["id"].split("-")[1])  # its place in bravo's task
    message = f"m.yaml: tasks.bravo[{index}].attempt: must be a whole number >= 1, got 0"
    assert str(caught.value) == message


def test_aliases_to_quickly_read_entries_count_in_full(library: Library) -> None:
    run = "".join(f'- {{"n": {i}, "text": "{"x" * 20}"}}\n' for i in range(2000))
    bomb = f"a: &run\n{run}b: [{', '.join(['*run'] * 5000)}]\n"
    with pytest.raises(MissionFileError, match="aliases expand it"):
        parse_mission(bomb, library, "bomb.yaml")
