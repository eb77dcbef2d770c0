"""Where a library's ``extends`` points: a path, or a file of a ROS package.

A library may name its base as a path from its own folder (``mars_team.yaml``), as an
absolute path, or as a file of a ROS package, the way launch files and rviz do:
``package://rosmc/rosmc_server/config/mars_team.yaml`` or
``$(find rosmc)/rosmc_server/config/mars_team.yaml``. So a lab's library in its own
package names the team it extends by package, whatever the share layout (a devel space,
a merged install, colcon's isolated ``install/<pkg>/share/<pkg>``).

Packages are found the way ``rospack`` finds them, through ``ROS_PACKAGE_PATH``: a folder
whose ``package.xml`` names the package. No ROS module is imported: the finder reads the
path it is given (:meth:`PackagePath.from_environ` reads the environment's).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

from ..errors import LibraryError

PackageFinder = Callable[[str], Path | None]
"""A package name -> its folder (the one holding its ``package.xml``), None if unknown."""

_REFERENCE = re.compile(
    r"^(?:package://(?P<url>[A-Za-z0-9_\-]+)|\$\(find (?P<find>[A-Za-z0-9_\-]+)\))(?P<rest>/.*)?$"
)
_NAME = re.compile(r"<name>\s*([^<\s]+)\s*</name>")
MAX_DEPTH = 4
"""Folders below a ``ROS_PACKAGE_PATH`` entry searched for a package (a workspace's src/...)."""


def package_reference(text: str) -> tuple[str, str] | None:
    """``(package, path inside it)`` of ``package://NAME/PATH`` or ``$(find NAME)/PATH``;
    None for a plain path."""
    found = _REFERENCE.match(text.strip())
    if found is None:
        return None
    return found["url"] or found["find"], (found["rest"] or "/").lstrip("/")


def resolve_reference(text: str, folder: Path, find_package: PackageFinder) -> Path:
    """The file ``text`` (an ``extends`` value) names, seen from a library in ``folder``.

    Raises:
        LibraryError: ``text`` names a package that ``find_package`` does not know.
    """
    reference = package_reference(text)
    if reference is None:
        return folder / text
    name, inside = reference
    root = find_package(name)
    if root is None:
        raise LibraryError(
            f"extends: {text}: no ROS package '{name}' on ROS_PACKAGE_PATH "
            "(source the setup.bash of the workspace that holds it)"
        )
    return root / inside


@dataclass(frozen=True)
class PackagePath:
    """Finds ROS packages below the folders of a ``ROS_PACKAGE_PATH``.

    Attributes:
        roots: The folders, in the order they are searched (the first match wins).
    """

    roots: tuple[Path, ...]

    @classmethod
    def parse(cls, value: str) -> PackagePath:
        """The finder of a ``ROS_PACKAGE_PATH`` value (folders separated by ``:``)."""
        return cls(tuple(Path(entry) for entry in value.split(os.pathsep) if entry))

    @classmethod
    def from_environ(cls, environ: Mapping[str, str] | None = None) -> PackagePath:
        """The finder of the environment's ``ROS_PACKAGE_PATH`` (``os.environ`` by default)."""
        return cls.parse((os.environ if environ is None else environ).get("ROS_PACKAGE_PATH", ""))

    def __call__(self, name: str) -> Path | None:
        """The folder of package ``name``, or None."""
        for root in self.roots:
            # The usual layout first (share/NAME, src/NAME), then a search below the root.
            for folder in (root, root / name, *_folders(root, MAX_DEPTH)):
                if _package_name(folder) == name:
                    return folder
        return None


def _package_name(folder: Path) -> str | None:
    try:
        text = (folder / "package.xml").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return None
    found = _NAME.search(text)
    return found.group(1) if found else None


def _folders(root: Path, depth: int) -> Iterator[Path]:
    """Folders below ``root`` that hold a package.xml, not below a package or CATKIN_IGNORE."""
    if depth == 0 or (root / "package.xml").is_file() or (root / "CATKIN_IGNORE").exists():
        return
    try:
        children = sorted(child for child in root.iterdir() if child.is_dir())
    except OSError:
        return
    for child in children:
        if child.name.startswith("."):
            continue
        if (child / "package.xml").is_file():
            yield child
        else:
            yield from _folders(child, depth - 1)
