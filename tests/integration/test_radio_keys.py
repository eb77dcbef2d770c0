"""The deployment's radio key: the documented ``rosmc key`` commands, and nodes that refuse
a key that is missing or open to others, in one sentence naming the file and the fix."""

from __future__ import annotations

import os
import shlex
import stat
import subprocess
import sys
from pathlib import Path

from rosmc_server.core.robots.radio_key import default_key_path, load_key, make_key
from tests.conftest import RosMaster, wait_until
from tests.integration.executor_fixtures import REPO_ROOT, RosmcSystem

ROSMC = REPO_ROOT / "scripts" / "rosmc"


def rosmc(command: str, home: Path) -> subprocess.CompletedProcess[str]:
    """Run a documented ``rosmc key`` command line with ``home`` as ROS_HOME."""
    argv = [sys.executable, str(ROSMC), *shlex.split(command)[1:]]
    env = {**os.environ, "ROS_HOME": str(home)}
    return subprocess.run(argv, env=env, capture_output=True, text=True, timeout=60, check=False)


def test_the_key_commands_make_show_and_rotate_a_private_key(tmp_path: Path) -> None:
    home = tmp_path / "ros_home"
    path = default_key_path({"ROS_HOME": str(home)})
    made = rosmc("rosmc key new", home)
    assert made.returncode == 0, made.stderr
    assert str(path) in made.stdout and "copy it to every host" in made.stdout
    assert stat.S_IMODE(path.stat().st_mode) == 0o600
    first = load_key(path)
    shown = rosmc("rosmc key show", home)
    assert shown.returncode == 0 and first.fingerprint in shown.stdout, shown
    again = rosmc("rosmc key new", home)
    assert again.returncode == 1 and "already exists" in again.stderr
    assert load_key(path).secret == first.secret, "an existing key is never overwritten"
    rotated = rosmc("rosmc key new --force", home)
    assert rotated.returncode == 0, rotated.stderr
    assert load_key(path).fingerprint != first.fingerprint
    assert first.fingerprint not in rosmc("rosmc key show", home).stdout


def test_nodes_refuse_a_key_open_to_others_or_missing_in_one_sentence(
    ros_master: RosMaster, tmp_path: Path
) -> None:
    shared = tmp_path / "shared.key"
    make_key(shared)
    shared.chmod(0o644)
    missing = tmp_path / "missing.key"
    system = RosmcSystem(ros_master.env, tmp_path / "system")
    try:
        system.start_executor("r1", False, f"_radio_key:={shared}")
        system.start_executor("r2", False, f"_radio_key:={missing}")
        system.start_server(f"_radio_key:={missing}")
        for name in ("r1", "r2", "server"):
            wait_until(lambda name=name: not system.alive(name), 60.0, f"{name} to refuse")
            assert system.processes[name].returncode == 1, name
        refused = system.log("r1").read_text()
        assert f"the radio key {shared} is open to other users (mode 0644)" in refused
        assert f"chmod 600 {shared}" in refused
        for name in ("r2", "server"):
            log = system.log(name).read_text()
            assert f"there is no radio key at {missing}" in log, log
            assert f"rosmc key new {missing}" in log
        assert not missing.exists(), "a key given by path is never made"
    finally:
        system.close()
