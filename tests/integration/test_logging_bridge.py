"""The logging bridge: our nodes' log lines do not ask the master anything, yet stay current.

rospy's rosout publisher reads ``/rosout_disable_topics_generation`` before every line;
unset (a bare ``roscore``), each read was an XML-RPC call to the master. A real node
(a subprocess on the session's master) bridges its logging, logs, and reports what
its parameter cache holds; the master then changes the flag and the node must see it.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from typing import IO, Any

from tests.conftest import REPO_ROOT, wait_until

NODE = textwrap.dedent(
    """
    import logging, sys, time
    import rospy, rospy.impl.paramserver
    from rosmc_server.common.ros.logging_bridge import ROSOUT_FLAG, bridge_logging_to_rosout

    rospy.init_node("logging_bridge_probe", disable_signals=True)
    bridge_logging_to_rosout()
    log = logging.getLogger("rosmc_server.probe")
    cache = rospy.impl.paramserver.get_param_server_cache()
    last = None
    for _ in range(600):
        log.info("probe line")
        value = cache.get(ROSOUT_FLAG)
        if value != last:
            print("FLAG", value, flush=True)
            last = value
        if value is True:
            break
        time.sleep(0.05)
    rospy.signal_shutdown("done")
    """
)


def next_flag(stream: IO[str]) -> str:
    """The next flag value the probe reports (its log lines go to stdout too)."""
    for line in stream:
        if line.startswith("FLAG "):
            return line.split()[1]
    return "<the probe ended>"


def test_the_rosout_flag_is_cached_and_follows_the_master(ros_master: Any) -> None:
    subprocess.run(
        ["rosparam", "delete", "/rosout_disable_topics_generation"],
        env=ros_master.env,
        capture_output=True,
        check=False,
    )
    probe = subprocess.Popen(
        [sys.executable, "-c", NODE],
        env=dict(ros_master.env),
        cwd=REPO_ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        assert probe.stdout is not None
        assert next_flag(probe.stdout) == "False"  # cached, not "unset"
        subprocess.run(
            ["rosparam", "set", "/rosout_disable_topics_generation", "true"],
            env=ros_master.env,
            check=True,
        )
        assert next_flag(probe.stdout) == "True"  # pushed by the master
        wait_until(lambda: probe.poll() is not None, timeout=30.0, what="the probe to end")
        assert probe.returncode == 0
    finally:
        if probe.poll() is None:
            probe.kill()
        probe.wait(10)
        subprocess.run(
            ["rosparam", "delete", "/rosout_disable_topics_generation"],
            env=ros_master.env,
            capture_output=True,
            check=False,
        )
