"""Writing files that survive a crash or a power loss (plain file system calls, no ROS)."""

import contextlib
import os
from pathlib import Path


def write_durably(target: Path, text: str) -> None:
    """Replace ``target`` with ``text`` (UTF-8) atomically and durably.

    A temporary file beside it is written and fsynced, renamed over ``target`` and the
    directory fsynced: after a crash or a power loss ``target`` holds either its old
    content or all of the new, and once this returns, the new.

    Raises:
        OSError: The file or its directory cannot be written (the target is unchanged).
    """
    temporary = target.with_name(f".{target.name}.tmp")
    try:
        with temporary.open("w", encoding="utf-8") as file:
            file.write(text)
            file.flush()
            os.fsync(file.fileno())
        temporary.replace(target)
    except OSError:
        with contextlib.suppress(OSError):  # e.g. a name too long to have been created at all
            temporary.unlink(missing_ok=True)
        raise
    fsync_directory(target.parent)


def fsync_directory(directory: Path) -> None:
    """Make the entries of ``directory`` durable (a file just created or renamed there)."""
    fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
