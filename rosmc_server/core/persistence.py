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

import contextlib
import os
from pathlib import Path

import yaml

from .documents import DuplicateKeyError, yaml_problem
from .errors import MissionFileError
from .library import Library
from .mission_reader import mission_from_dict
from .mission_text import MISSION_VERSION, MissionDumper, mission_to_dict, read_document
from .state import MissionContent

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
    """Write a mission document to ``path`` atomically and durably.

    The text goes to a temporary file beside the target, which is flushed to the disk
    and renamed over the target; the directory is flushed too, so after a crash or a
    power loss the file holds either the previous save or this one, complete.
    """
    target = Path(path)
    temporary = target.with_name(f".{target.name}.tmp")
    try:
        fd = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        try:
            view = memoryview(document.encode("utf-8"))
            while view:
                view = view[os.write(fd, view) :]
            os.fsync(fd)
        finally:
            os.close(fd)
        temporary.replace(target)
        _fsync_directory(target.parent)
    except OSError as error:
        with contextlib.suppress(OSError):  # e.g. the name is too long to exist at all
            temporary.unlink()
        raise MissionFileError(f"{target}: cannot write the mission ({error.strerror})") from error


def _fsync_directory(directory: Path) -> None:
    """Flush a directory's entries (a rename in it) to the disk."""
    fd = os.open(directory, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def load_mission(path: str | Path, library: Library) -> tuple[MissionContent, int]:
    """Read and check a mission file; return its content and revision."""
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
    try:
        data = read_document(text, source)
    except DuplicateKeyError as error:
        raise MissionFileError(f"{source}: not valid YAML ({yaml_problem(error)})") from error
    except yaml.constructor.ConstructorError as error:
        raise MissionFileError(
            f"{source}: refused a YAML tag that is not plain data ({error.problem})"
        ) from error
    except yaml.YAMLError as error:
        raise MissionFileError(f"{source}: not valid YAML ({yaml_problem(error)})") from error
    return mission_from_dict(data, library, source)
