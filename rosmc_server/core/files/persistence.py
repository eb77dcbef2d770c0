"""Mission files: versioned YAML, read with a safe loader only.

A file holds the mission's tasks, barriers, task markers, revision and the
name of its library. Loading checks everything against the library and the
mission rules and fails with one sentence naming the file and the problem;
nothing is half-loaded. Python object tags are refused, never executed, and
so are YAML aliases that expand a document beyond reason.

Each skill is one line of the file (see :mod:`.mission_text`), which keeps saving and
loading a mission of 10,000 skills within a tenth of a second; :mod:`.mission_reader`
checks what was read.
"""

from __future__ import annotations

from pathlib import Path

import yaml

from ..documents.documents import DuplicateKeyError, yaml_problem
from ..documents.durable import write_durably
from ..errors import MissionFileError
from ..model.state import MissionContent
from ..skills.library import Library
from ..validation import check_encodable, check_file_path
from .document_reading import read_document
from .mission_reader import mission_from_dict
from .mission_text import MISSION_VERSION, MissionDumper, mission_to_dict

__all__ = [
    "MISSION_VERSION",
    "MissionDumper",
    "dump_mission",
    "load_mission",
    "mission_from_dict",
    "mission_to_dict",
    "parse_mission",
    "save_mission",
    "write_document",
]


def dump_mission(content: MissionContent, revision: int) -> str:
    """The mission as a YAML document."""
    return MissionDumper().dump(content, revision)


def save_mission(path: str | Path, content: MissionContent, revision: int) -> None:
    """Write the mission to ``path`` atomically and durably (see :func:`write_document`)."""
    write_document(path, dump_mission(content, revision))


def write_document(path: str | Path, document: str) -> None:
    """Write a mission document to ``path`` atomically and durably (see :func:`write_durably`):
    after a crash or a power loss the file holds either the previous save or this one."""
    check_file_path(str(path))
    try:
        write_durably(Path(path), document)
    except OSError as error:
        raise MissionFileError(f"{path}: cannot write the mission ({error.strerror})") from error


def load_mission(path: str | Path, library: Library) -> tuple[MissionContent, int]:
    """Read and check a mission file; return its content and revision."""
    check_file_path(str(path))
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as error:
        raise MissionFileError(f"{path}: cannot read the mission ({error.strerror})") from error
    except UnicodeDecodeError as error:
        problem = f"the file is not UTF-8 text (byte {error.start})"
        raise MissionFileError(f"{path}: {problem}") from error
    return parse_mission(text, library, str(path))


def parse_mission(text: str, library: Library, source: str) -> tuple[MissionContent, int]:
    """Parse and check a mission document; return its content and revision."""
    check_encodable(text, f"the mission document {source}")
    try:
        data = read_document(text, source, plain_tasks=True)
    except DuplicateKeyError as error:
        raise MissionFileError(f"{source}: not valid YAML ({yaml_problem(error)})") from error
    except yaml.constructor.ConstructorError as error:
        raise MissionFileError(
            f"{source}: refused a YAML tag that is not plain data ({error.problem})"
        ) from error
    except yaml.YAMLError as error:
        raise MissionFileError(f"{source}: not valid YAML ({yaml_problem(error)})") from error
    return mission_from_dict(data, library, source, consume=True)
