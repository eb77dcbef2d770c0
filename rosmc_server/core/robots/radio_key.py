"""The deployment's radio key: one shared secret that signs every radio datagram.

Every host of one deployment (the ground station and each robot) holds a copy of the same
key file; nothing travels over ROS to share it, since ROS topics and parameters carry no
secrecy. The file is text, two lines::

    rosmc-radio-key 1
    <64 hexadecimal digits: 32 random bytes from the operating system's generator>

It must be a regular file that only its owner may read or write (mode 0600): a key that
others can read signs nothing anyone can trust. :func:`make_key` writes it so, atomically
(a reader never sees half a key, and two nodes that start together and both make the
default key end up with one key between them); :func:`load_key` refuses anything else in
one sentence that names the file and the fix.

Where it lives: a node's ``~radio_key`` parameter, else :func:`default_key_path`
(``$ROS_HOME/rosmc/radio.key``). A node makes the key at the default place when none
exists there (one host: the README's commands need no setup), never at a path it was given:
there a missing key is an error, as on a robot whose copy was forgotten.
"""

from __future__ import annotations

import hashlib
import os
import secrets
import stat
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import RadioKeyError

KEY_BYTES = 32
HEADER = "rosmc-radio-key 1"
KEY_DIR = "rosmc"
KEY_NAME = "radio.key"


@dataclass(frozen=True)
class RadioKey:
    """A deployment's radio key and the file it came from (the secret never prints)."""

    secret: bytes = field(repr=False)
    path: Path

    @property
    def fingerprint(self) -> str:
        """16 hex digits that name the key without revealing it: compare them across hosts."""
        return hashlib.sha256(b"rosmc radio key fingerprint\n" + self.secret).hexdigest()[:16]


def default_key_path(environ: Mapping[str, str]) -> Path:
    """``$ROS_HOME/rosmc/radio.key`` (``~/.ros`` when ROS_HOME is unset), as ROS places files."""
    home = environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    return Path(home) / KEY_DIR / KEY_NAME


def key_text(secret: bytes) -> str:
    """The file's content for ``secret``."""
    return f"{HEADER}\n{secret.hex()}\n"


def make_key(
    path: Path, replace: bool = False, random: Callable[[int], bytes] = secrets.token_bytes
) -> RadioKey:
    """Write a new key to ``path`` (mode 0600) and return it.

    Raises RadioKeyError if a key is there already and ``replace`` is False: replacing a
    deployment's key cuts every host that still has the old one off the radio.
    """
    path = Path(path)
    secret = random(KEY_BYTES)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.{secrets.token_hex(4)}")
    descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    try:
        with os.fdopen(descriptor, "w", encoding="ascii") as handle:
            handle.write(key_text(secret))
            handle.flush()
            os.fsync(handle.fileno())
        if replace:
            os.replace(temporary, path)
        else:
            try:
                os.link(temporary, path)  # fails if the key exists: never overwrite one
            except FileExistsError:
                raise RadioKeyError(
                    f"a radio key already exists at {path}; keep it, or replace it with "
                    f"`rosmc key new --force {path}` and copy the new one to every host"
                ) from None
    finally:
        temporary.unlink(missing_ok=True)
    return RadioKey(secret, path)


def load_key(path: Path) -> RadioKey:
    """The key in ``path``; RadioKeyError, naming the file and the fix, if it is unusable."""
    path = Path(path)
    try:
        info = path.stat()
    except FileNotFoundError:
        raise RadioKeyError(
            f"there is no radio key at {path}; copy the deployment's key there, or make one "
            f"with `rosmc key new {path}` and copy it to every host"
        ) from None
    except OSError as error:
        raise RadioKeyError(f"cannot read the radio key {path}: {error.strerror}") from None
    if not stat.S_ISREG(info.st_mode):
        raise RadioKeyError(f"the radio key {path} is not a regular file")
    mode = stat.S_IMODE(info.st_mode)
    if mode & 0o077:
        raise RadioKeyError(
            f"the radio key {path} is open to other users (mode {mode:04o}); make it private "
            f"with `chmod 600 {path}`, and as others may have read it, rotate it with "
            f"`rosmc key new --force {path}`"
        )
    try:
        lines = path.read_text(encoding="ascii").split()
    except (OSError, UnicodeDecodeError) as error:
        raise RadioKeyError(f"cannot read the radio key {path}: {error}") from None
    secret = _secret(lines)
    if secret is None:
        raise RadioKeyError(
            f"{path} is not a rosmc radio key ('{HEADER}' and {2 * KEY_BYTES} hex digits); "
            f"make one with `rosmc key new --force {path}`"
        )
    return RadioKey(secret, path)


def _secret(words: list[str]) -> bytes | None:
    if len(words) != 3 or " ".join(words[:2]) != HEADER or len(words[2]) != 2 * KEY_BYTES:
        return None
    try:
        return bytes.fromhex(words[2])
    except ValueError:
        return None


def obtain_key(path: Path | None, environ: Mapping[str, str]) -> tuple[RadioKey, bool]:
    """A node's key: from ``path``, else from the default place, made there if missing.

    Returns the key and whether it was just made (the node then says so: every other host
    of the deployment needs a copy).
    """
    if path is not None:
        return load_key(path), False
    default = default_key_path(environ)
    if not default.exists():
        try:
            return make_key(default), True
        except RadioKeyError:  # another node made it a moment ago: use that one
            pass
    return load_key(default), False
