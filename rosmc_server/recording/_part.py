"""One open file of a journal: the records written to it and how it is closed."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from rosmc_server.core.durable import fsync_directory
from rosmc_server.recording import _format as fmt
from rosmc_server.recording._files import open_locked
from rosmc_server.recording._section import DataSection
from rosmc_server.recording.channels import JOURNAL_TOPICS, LIBRARY, PROFILE
from rosmc_server.recording.errors import JournalError


@dataclass
class PartFile:
    """A locked journal file being appended to, positioned at its end.

    Attributes:
        path: The file.
        number: Its place in the journal's chain (1 for the first file).
        fd: The open descriptor (None once closed).
        section: What its data section holds (for the summary written on close).
        offset: Bytes handed to the operating system so far (the file size while open).
        chunked: Whether each append is written as its own chunk.
        snapshots: Snapshots in it (a part without one cannot start a mission).
    """

    path: Path
    number: int
    fd: int | None
    section: DataSection
    offset: int
    chunked: bool
    snapshots: int = 0

    @classmethod
    def create(cls, path: Path, number: int, chunked: bool, durable: bool) -> PartFile:
        """Create a new file with the MCAP header and every journal channel declared.

        Raises:
            JournalError: The file exists or cannot be written.
        """
        fd = open_locked(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
        part = cls(path, number, fd, DataSection(), 0, chunked)
        preamble = fmt.MAGIC + fmt.header(PROFILE, LIBRARY) + part.section.declare(JOURNAL_TOPICS)
        try:
            part.write(preamble, sync=False, durable=False)
            if durable:
                fsync_directory(path.parent)
        except (OSError, JournalError) as err:
            part.abandon()
            path.unlink()  # it holds nothing anybody was told about
            if isinstance(err, JournalError):
                raise
            raise JournalError(f"cannot create journal {path}: {err.strerror}") from err
        return part

    def write(self, data: bytes, sync: bool, durable: bool) -> None:
        """Write all of ``data`` at the end (fdatasync if ``sync and durable``).

        On failure the file is cut back to where it was and JournalError raised.
        """
        fd = self.open_fd()
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view) :]
            if sync and durable:
                os.fdatasync(fd)
        except OSError as err:
            try:  # a partial record must not stay in front of the next append
                os.ftruncate(fd, self.offset)
                os.lseek(fd, self.offset, os.SEEK_SET)
            except OSError:
                self.abandon()
            raise JournalError(f"cannot write journal {self.path}: {err.strerror}") from err
        self.offset += len(data)

    def sync(self) -> None:
        """fdatasync the file."""
        try:
            os.fdatasync(self.open_fd())
        except OSError as err:
            raise JournalError(f"cannot sync journal {self.path}: {err.strerror}") from err

    def close(self) -> None:
        """Write the summary and footer, sync and close: the file is complete MCAP."""
        if self.fd is None:
            return
        try:
            self.write(self.section.closing_bytes(self.offset), sync=False, durable=False)
            os.fdatasync(self.open_fd())
        except OSError as err:
            raise JournalError(f"cannot close journal {self.path}: {err.strerror}") from err
        finally:
            self.abandon()

    def abandon(self) -> None:
        """Close the file without a summary, as a crash leaves it."""
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def open_fd(self) -> int:
        """The descriptor; JournalError if the file is closed."""
        if self.fd is None:
            raise JournalError(f"journal {self.path} is closed")
        return self.fd
