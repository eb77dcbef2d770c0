"""The shared ``ros_master`` and ``launch_process`` fixtures work against real ROS tools."""

from __future__ import annotations

import os
import subprocess
import time

import pytest


def test_master_answers_system_state(ros_master) -> None:
    code, _message, state = ros_master.proxy().getSystemState("/test")
    assert code == 1
    assert [type(part) for part in state] == [list, list, list]  # publishers, subscribers, services
    assert ros_master.uri.startswith("http://127.0.0.1:")
    assert os.environ["ROS_MASTER_URI"] == ros_master.uri


def test_subprocess_env_reaches_the_master(ros_master) -> None:
    subprocess.run(["rosparam", "set", "/rosmc_test/answer", "42"], env=ros_master.env, check=True)
    code, _message, value = ros_master.proxy().getParam("/test", "/rosmc_test/answer")
    assert (code, value) == (1, 42)


def test_launched_node_registers_and_is_stopped(ros_master, launch_process) -> None:
    topic = "/rosmc_test/chatter"
    node = launch_process(
        ["rostopic", "pub", "-r", "10", topic, "std_msgs/String", "data: hello"],
        env=ros_master.env,
        name="chatter",
    )
    deadline = time.monotonic() + 60.0
    published: list[str] = []
    while time.monotonic() < deadline and topic not in published:
        assert node.poll() is None, node.log()
        _code, _message, topics = ros_master.proxy().getPublishedTopics("/test", "")
        published = [name for name, _type in topics]
        time.sleep(0.1)
    assert topic in published, node.log()


@pytest.mark.parametrize("key", ["ROS_IP", "ROS_HOME", "ROS_LOG_DIR"])
def test_master_env_is_private_and_loopback(ros_master, key) -> None:
    value = ros_master.env[key]
    if key == "ROS_IP":
        assert value == "127.0.0.1"
    else:
        assert value.startswith(str(ros_master.home))
    assert "ROS_HOSTNAME" not in ros_master.env
