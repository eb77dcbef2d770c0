"""``rosmc key new [PATH]`` and ``rosmc key show [PATH]``: the deployment's radio key.

No ROS master needed: they read and write the key file only (see
:mod:`rosmc_server.core.robots.radio_key`).
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from ..core.robots.radio_key import default_key_path, load_key, make_key

if TYPE_CHECKING:
    from .context import Context

_Command = Callable[..., argparse.ArgumentParser]

KEY_HELP = """\
The radio key signs every datagram of the radio side channel (barrier signals,
beacons); a host without it cannot speak there. Every host of one deployment
needs the same key file (mode 0600). PATH defaults to $ROS_HOME/rosmc/radio.key
(~/.ros/rosmc/radio.key), where the nodes look unless given _radio_key:=PATH.

  new   make a key (refused if one exists; --force replaces it: rotation)
  show  check a key and print its fingerprint (compare it across hosts)"""


def add_commands(command: _Command) -> None:
    """Add ``rosmc key`` through the parser's ``command`` helper."""
    key = command("key", "make or check the deployment's radio key", KEY_HELP)
    key.add_argument("action", choices=("new", "show"), help="what to do")
    key.add_argument("path", nargs="?", metavar="PATH", help="the key file")
    key.add_argument(
        "--force", action="store_true", help="with new: replace an existing key (rotation)"
    )


def key(ctx: Context) -> int:
    """Make or check a key file; print its path and fingerprint."""
    path = Path(ctx.args.path) if ctx.args.path else default_key_path(os.environ)
    if ctx.args.action == "new":
        made = make_key(path, replace=ctx.args.force)
        line = (
            f"made the radio key {made.path} (fingerprint {made.fingerprint}); copy it to "
            "every host of the deployment, mode 0600, and restart their nodes"
        )
        ctx.emit(line, {"path": str(made.path), "fingerprint": made.fingerprint, "made": True})
        return 0
    found = load_key(path)
    line = f"{found.path}: a radio key, fingerprint {found.fingerprint}"
    ctx.emit(line, {"path": str(found.path), "fingerprint": found.fingerprint, "made": False})
    return 0


COMMANDS = {"key": key}
