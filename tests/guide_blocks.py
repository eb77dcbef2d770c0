"""The code blocks of ``docs/writing-skills.md``, for the tests that run them.

Each block's first line names it (``# sweeper_lab.yaml``), except the shell command.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
GUIDE = REPO / "docs" / "writing-skills.md"
MARS = REPO / "rosmc_server" / "config" / "mars_team.yaml"
_BLOCK = re.compile(r"^```(\w+)\n(.*?)^```$", re.DOTALL | re.MULTILINE)


def blocks(language: str) -> list[str]:
    """Every fenced block of ``language`` in the guide, in order."""
    return [body for lang, body in _BLOCK.findall(GUIDE.read_text()) if lang == language]


def file_name(block: str) -> str:
    """The file a block is, from its first line (``# name.ext: ...``)."""
    first = block.splitlines()[0]
    assert first.startswith("# "), f"a guide block without its file name: {first!r}"
    return first[2:].split(":")[0].strip()


def write_files(folder: Path) -> dict[str, Path]:
    """Write every YAML and Python block under its name in ``folder``, beside the Mars
    library that the extending examples name; returns the paths by name."""
    shutil.copy(MARS, folder / MARS.name)
    written = {}
    for block in blocks("yaml") + blocks("python"):
        path = folder / file_name(block)
        path.write_text(block, encoding="utf-8")
        written[path.name] = path
    return written
