#!/usr/bin/env python3
"""Generate docs/reference.md's reference part: node parameters, messages and services.

The generated part sits in docs/reference.md between ``<!-- BEGIN MSG REFERENCE -->`` and
``<!-- END MSG REFERENCE -->``. Usage::

    python tools/gen_msg_reference.py           # print the generated part
    python tools/gen_msg_reference.py --check   # exit 1 if docs/reference.md is out of date
    python tools/gen_msg_reference.py --write   # rewrite the part in docs/reference.md

Messages and services come from rosmc_msgs/msg and rosmc_msgs/srv: each type gets its
leading comment as a description, a table of constants and a table of fields (type, name,
the field's comment). Comment lines between definitions are attached to the definition below
them, but an indented one right after a commented definition goes on with that comment.
Field types that are rosmc types link to their own section.

Node parameters come from each node's module: every private parameter the
code reads with ``rospy.get_param("~name", default)``, its default when it is a literal, and
what the module's docstring says of it (:mod:`node_params_reference`).
"""

from __future__ import annotations

import argparse
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from node_params_reference import render as render_node_parameters

REPO_ROOT = Path(__file__).resolve().parent.parent
MSG_DIR = REPO_ROOT / "rosmc_msgs" / "msg"
SRV_DIR = REPO_ROOT / "rosmc_msgs" / "srv"
DOC = REPO_ROOT / "docs" / "reference.md"
BEGIN = "<!-- BEGIN MSG REFERENCE -->"
END = "<!-- END MSG REFERENCE -->"
PACKAGE = "rosmc"

_CONSTANT = re.compile(r"^(?P<type>\S+)\s+(?P<name>[A-Za-z_]\w*)\s*=\s*(?P<rest>.*)$")
_FIELD = re.compile(r"^(?P<type>\S+)\s+(?P<name>[A-Za-z_]\w*)\s*(?:#\s?(?P<comment>.*))?$")


@dataclass
class Constant:
    """``TYPE NAME=VALUE  # comment``."""

    type: str
    name: str
    value: str
    comment: str


@dataclass
class Field:
    """``TYPE NAME  # comment``."""

    type: str
    name: str
    comment: str


@dataclass
class Section:
    """The definitions of one message, or of one half of a service."""

    description: list[str] = field(default_factory=list)
    constants: list[Constant] = field(default_factory=list)
    fields: list[Field] = field(default_factory=list)


def _comment_text(line: str) -> str:
    """The text of a ``#`` comment line, keeping indentation beyond one space."""
    text = line.lstrip()[1:]
    return text[1:] if text.startswith(" ") else text


def parse_section(lines: list[str], leading_description: bool) -> Section:
    """Parse the lines of a .msg file (or of one side of a .srv file)."""
    section = Section()
    pending: list[str] = []  # comment lines waiting for the definition below them
    previous: Field | Constant | None = None  # the commented definition just above
    in_header = leading_description
    for raw in lines:
        line = raw.rstrip()
        stripped = line.strip()
        if not stripped:
            previous = None
            if in_header and pending:
                section.description.extend(pending)
                pending = []
            in_header = False
            continue
        if stripped.startswith("#"):
            if previous is not None and not pending and raw[:1].isspace():
                # an indented comment line goes on with the comment of the line above
                previous.comment = _join(previous.comment, _comment_text(stripped).strip())
            else:
                pending.append(_comment_text(stripped))
            continue
        if in_header:
            # A last header line ending in ':' heads the definitions below it instead.
            keep = len(pending) - 1 if len(pending) > 1 and pending[-1].endswith(":") else None
            section.description.extend(pending[:keep])
            pending = pending[keep:] if keep is not None else []
            in_header = False
        if pending and pending[-1].endswith(":"):
            heading = " ".join(text.strip() for text in pending)
            target = section.constants if _CONSTANT.match(stripped) else section.fields
            target.append(_group_row(target is section.constants, heading))
            pending = []
        note = " ".join(text.strip() for text in pending)
        pending = []
        constant = _CONSTANT.match(stripped)
        if constant:
            value, comment = _split_constant(constant.group("type"), constant.group("rest"))
            section.constants.append(
                Constant(
                    constant.group("type"), constant.group("name"), value, _join(note, comment)
                )
            )
            previous = section.constants[-1] if comment else None
            continue
        parsed = _FIELD.match(stripped)
        if not parsed:
            raise ValueError(f"cannot parse definition line: {raw!r}")
        comment = (parsed.group("comment") or "").strip()
        section.fields.append(
            Field(parsed.group("type"), parsed.group("name"), _join(note, comment))
        )
        previous = section.fields[-1] if comment else None
    if in_header:
        section.description.extend(pending)
    return section


def _group_row(constant: bool, heading: str) -> Constant | Field:
    """A table row that heads the definitions below it (a comment ending in ':')."""
    if constant:
        return Constant("", "", "", heading)
    return Field("", "", heading)


def _split_constant(type_: str, rest: str) -> tuple[str, str]:
    if type_ == "string":  # a string constant's value is the whole rest of the line
        return rest.strip(), ""
    value, _, comment = rest.partition("#")
    return value.strip(), comment.strip()


def _join(note: str, comment: str) -> str:
    if note and comment:
        return f"{note} {comment}"
    return note or comment


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _type_cell(type_: str, known: set[str]) -> str:
    base = re.sub(r"\[\d*\]$", "", type_)
    suffix = type_[len(base) :]
    name = base.split("/")[-1] if base.startswith(f"{PACKAGE}/") else base
    if name in known:
        return f"[`{name}`](#{name.lower()}){suffix and f'`{suffix}`'}"
    return f"`{type_}`"


def _render_description(lines: list[str]) -> list[str]:
    """Prose lines become one paragraph; indented lines (aligned lists) a text block."""
    out: list[str] = []
    prose: list[str] = []
    block: list[str] = []
    for line in [*lines, ""]:
        if line.startswith(" ") and line.strip():
            if prose:
                out += [" ".join(prose), ""]
                prose = []
            block.append(line.strip())
            continue
        if block:
            out += ["```text", *block, "```", ""]
            block = []
        if line.strip():
            prose.append(line.strip())
    if prose:
        out += [" ".join(prose), ""]
    return out


def render_section(section: Section, known: set[str], heading: str | None = None) -> list[str]:
    """Markdown for one section: description, constants table, fields table."""
    out: list[str] = []
    if heading:
        out += [heading, ""]
    out += _render_description(section.description)
    if section.constants:
        out += ["| Constant | Type | Value | Meaning |", "| --- | --- | --- | --- |"]
        out += [
            f"| `{c.name}` | `{c.type}` | `{c.value}` | {_cell(c.comment)} |"
            if c.name
            else f"| *{_cell(c.comment)}* | | | |"
            for c in section.constants
        ]
        out.append("")
    if section.fields:
        out += ["| Field | Type | Meaning |", "| --- | --- | --- |"]
        out += [
            f"| `{f.name}` | {_type_cell(f.type, known)} | {_cell(f.comment)} |"
            if f.name
            else f"| *{_cell(f.comment)}* | | |"
            for f in section.fields
        ]
        out.append("")
    elif not section.constants:
        out += ["*(no fields)*", ""]
    return out


def _split_srv(text: str) -> tuple[list[str], list[str]]:
    lines = text.splitlines()
    for index, line in enumerate(lines):
        if line.strip() == "---":
            return lines[:index], lines[index + 1 :]
    raise ValueError("a .srv file needs a '---' line")


def _summary(description: list[str]) -> str:
    prose = " ".join(line.strip() for line in description if not line.startswith(" "))
    first = re.split(r"(?<=\.)\s", prose, maxsplit=1)[0]
    return _cell(first)


def generate(msg_dir: Path = MSG_DIR, srv_dir: Path = SRV_DIR) -> str:
    """The whole generated part, markers included."""
    msg_files = sorted(msg_dir.glob("*.msg"))
    srv_files = sorted(srv_dir.glob("*.srv"))
    known = {path.stem for path in msg_files}
    messages = {p.stem: parse_section(p.read_text().splitlines(), True) for p in msg_files}
    services = {}
    for path in srv_files:
        request_lines, response_lines = _split_srv(path.read_text())
        services[path.stem] = (
            parse_section(request_lines, True),
            parse_section(response_lines, False),
        )

    out = [
        BEGIN,
        "<!-- Generated by tools/gen_msg_reference.py from rosmc_msgs/ and the node modules;",
        "     edit those and run `python tools/gen_msg_reference.py --write`. -->",
        "",
        *render_node_parameters(),
        "## Messages and services",
        "",
        f"Messages import as `rosmc.msg`, services as `rosmc.srv` "
        f"({len(messages)} messages, {len(services)} services).",
        "",
        "## Messages",
        "",
        "| Message | Purpose |",
        "| --- | --- |",
    ]
    out += [
        f"| [`{name}`](#{name.lower()}) | {_summary(sec.description)} |"
        for name, sec in messages.items()
    ]
    out += ["", "## Services", "", "| Service | Purpose |", "| --- | --- |"]
    out += [
        f"| [`{name}`](#{name.lower()}) | {_summary(request.description)} |"
        for name, (request, _response) in services.items()
    ]
    out.append("")
    out += ["## Message definitions", ""]
    for name, section in messages.items():
        out += render_section(section, known, f"### {name}")
    out += ["## Service definitions", ""]
    for name, (request, response) in services.items():
        out += [f"### {name}", ""]
        description, request.description = request.description, []
        out += _render_description(description)
        out += render_section(request, known, "Request:")
        out += render_section(response, known, "Response:")
    while out[-1] == "":
        out.pop()
    out.append(END)
    return "\n".join(out) + "\n"


def replace_section(document: str, section: str) -> str:
    """``document`` with the text between (and including) the markers replaced by ``section``."""
    start = document.find(BEGIN)
    end = document.find(END)
    if start < 0 or end < start:
        raise ValueError(f"docs/reference.md needs the markers {BEGIN} and {END}")
    return document[:start] + section + document[end + len(END) :].removeprefix("\n")


def main(argv: list[str] | None = None) -> int:
    """Print, check or write the reference; returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--write", action="store_true", help="rewrite the part in the document")
    group.add_argument("--check", action="store_true", help="fail if the document is out of date")
    args = parser.parse_args(argv)

    section = generate()
    if not (args.write or args.check):
        sys.stdout.write(section)
        return 0
    current = DOC.read_text()
    wanted = replace_section(current, section)
    if args.check:
        if wanted != current:
            print(f"{DOC.name}'s generated reference is out of date; run "
                  "python tools/gen_msg_reference.py --write", file=sys.stderr)  # fmt: skip
            return 1
        return 0
    if wanted != current:
        DOC.write_text(wanted)
        print(f"{DOC.name}: generated reference updated")
    return 0


if __name__ == "__main__":
    sys.exit(main())
