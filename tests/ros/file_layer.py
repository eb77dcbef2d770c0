"""A test file layer: every change the code under test makes to the files of one folder,
in order, so that the folder can be rebuilt as any crash would have left it.

Like SQLite's test VFS, it sits under the code, not beside it: while :meth:`FileLog.
recording` is active, ``os.open`` (creations), ``os.write``/``os.writev``/``os.pwrite`` and
``os.ftruncate`` and ``os.replace`` on files below the folder are performed for real and
logged. A crash at
any point is then :meth:`FileLog.rebuild`: the operations before it applied in order to an
empty folder, and optionally the first bytes of the one it interrupted (a torn write). A
process crash loses nothing the kernel was handed, so this is exactly what a ``kill -9``
between any two system calls, or in the middle of one write, leaves behind.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest


@dataclass(frozen=True)
class Op:
    """One change to a file: ``create``, ``write`` (at ``offset``), ``truncate`` (to
    ``offset``), ``rename`` (to ``label``), or a ``note`` the test made between changes
    (``label``)."""

    kind: str
    name: str = ""
    offset: int = 0
    data: bytes = b""
    label: Any = None


class FileLog:
    """The changes made below ``root`` while recording."""

    def __init__(self, root: Path) -> None:
        self.root = root.resolve()
        self.ops: list[Op] = []

    def note(self, label: Any) -> None:
        """Put a marker between changes (an acknowledgement, say)."""
        self.ops.append(Op("note", label=label))

    @contextmanager
    def recording(self, monkeypatch: pytest.MonkeyPatch) -> Iterator[FileLog]:
        """Log every change to files below ``root`` until the block ends."""
        real_open, real_write, real_writev = os.open, os.write, os.writev
        real_pwrite, real_ftruncate, real_replace = os.pwrite, os.ftruncate, os.replace

        def name_of(fd: int) -> str | None:
            try:
                path = Path(os.readlink(f"/proc/self/fd/{fd}"))
            except OSError:
                return None
            return str(path.relative_to(self.root)) if path.is_relative_to(self.root) else None

        def logged_open(path: Any, flags: int, mode: int = 0o777, **kwargs: Any) -> int:
            existed = os.path.exists(path)
            fd = real_open(path, flags, mode, **kwargs)
            name = name_of(fd)
            if name is not None and flags & os.O_CREAT and not existed:
                self.ops.append(Op("create", name))
            return fd

        def logged_write(fd: int, data: Any) -> int:
            offset = os.lseek(fd, 0, os.SEEK_CUR)
            written = real_write(fd, data)
            self._wrote(name_of(fd), offset, bytes(data)[:written])
            return written

        def logged_writev(fd: int, buffers: Any) -> int:
            offset = os.lseek(fd, 0, os.SEEK_CUR)
            written = real_writev(fd, buffers)
            self._wrote(name_of(fd), offset, b"".join(bytes(b) for b in buffers)[:written])
            return written

        def logged_pwrite(fd: int, data: Any, offset: int) -> int:
            written = real_pwrite(fd, data, offset)
            self._wrote(name_of(fd), offset, bytes(data)[:written])
            return written

        def logged_ftruncate(fd: int, length: int) -> None:
            real_ftruncate(fd, length)
            name = name_of(fd)
            if name is not None:
                self.ops.append(Op("truncate", name, length))

        def logged_replace(source: Any, target: Any, **kwargs: Any) -> None:
            real_replace(source, target, **kwargs)
            names = [Path(p).resolve() for p in (source, target)]
            if all(p.is_relative_to(self.root) for p in names):
                old, new = (str(p.relative_to(self.root)) for p in names)
                self.ops.append(Op("rename", old, label=new))

        with monkeypatch.context() as patch:
            patch.setattr(os, "open", logged_open)
            patch.setattr(os, "write", logged_write)
            patch.setattr(os, "writev", logged_writev)
            patch.setattr(os, "pwrite", logged_pwrite)
            patch.setattr(os, "ftruncate", logged_ftruncate)
            patch.setattr(os, "replace", logged_replace)
            yield self

    def _wrote(self, name: str | None, offset: int, data: bytes) -> None:
        if name is not None and data:
            self.ops.append(Op("write", name, offset, data))

    def rebuild(self, upto: int, torn: int, into: Path) -> None:
        """Make ``into`` hold the files as after ``ops[:upto]``, plus the first ``torn`` bytes
        of ``ops[upto]`` when it is a write (0: none)."""
        into.mkdir(parents=True, exist_ok=True)
        ops = list(self.ops[:upto])
        if torn and upto < len(self.ops) and self.ops[upto].kind == "write":
            cut = self.ops[upto]
            ops.append(Op("write", cut.name, cut.offset, cut.data[:torn]))
        files: dict[str, bytearray] = {}
        for op in ops:
            if op.kind == "create":
                files[op.name] = bytearray()
            elif op.kind == "write":
                content = files.setdefault(op.name, bytearray())
                end = op.offset + len(op.data)
                if len(content) < end:
                    content.extend(b"\0" * (end - len(content)))
                content[op.offset : end] = op.data
            elif op.kind == "rename":
                files[op.label] = files.pop(op.name, bytearray())
            elif op.kind == "truncate":
                content = files.setdefault(op.name, bytearray())
                del content[op.offset :]
                content.extend(b"\0" * (op.offset - len(content)))
        for name, content in files.items():
            target = into / name
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(bytes(content))

    def notes_before(self, upto: int) -> list[Any]:
        """The labels noted before ``ops[upto]``, in order."""
        return [op.label for op in self.ops[:upto] if op.kind == "note"]
