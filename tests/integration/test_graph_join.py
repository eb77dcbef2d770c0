"""A node that respawns under its name never shuts down a process that took its old port.

rosmaster keeps a node killed with -9 registered at its old XML-RPC URI. The tests
reproduce the moment the hazard bites (another node has been given that port) exactly,
by registering the dead node's topics at a live stranger's URI, which is what the master
holds then. A plain ``rospy.init_node`` shuts the stranger down; ``join_graph`` and the
real mission server leave it running.
"""

from __future__ import annotations

import sys
import textwrap
from typing import Any

import pytest
import rosgraph

from rosmc_server import interface
from rosmc_server.common.ros.graph_join import clear_stale_registration
from tests.conftest import free_port, wait_until

pytest_plugins = ["tests.integration.server_fixtures"]
pytestmark = pytest.mark.integration

START = 60.0
BUMPED = "new node registered with same name"

NODE_SCRIPT = textwrap.dedent(
    """
    import sys
    import rospy
    import std_msgs.msg
    from rosmc_server.common.ros.graph_join import join_graph

    name, topic, how = sys.argv[1:4]
    name = name.lstrip("/")  # a base name; the test gives the graph name
    if how == "join_graph":
        join_graph(name, disable_signals=True)
    else:
        rospy.init_node(name, disable_signals=True)
    rospy.Publisher(topic, std_msgs.msg.String, queue_size=1, latch=True).publish("up")
    rospy.spin()
    """
)


def master_of(node: str, ros_master: Any) -> rosgraph.Master:
    """The master API as ``node`` would call it."""
    return rosgraph.Master(node, master_uri=ros_master.uri)


def registered_uri(node: str, ros_master: Any) -> str | None:
    """The URI the master holds for ``node``, or None."""
    try:
        return str(master_of("/pytest", ros_master).lookupNode(node))
    except rosgraph.MasterError:
        return None


def publishers(topic: str, ros_master: Any) -> list[str]:
    """The nodes the master lists as publishers of ``topic``."""
    published, _subscribed, _services = master_of("/pytest", ros_master).getSystemState()
    return next((nodes for name, nodes in published if name == topic), [])


def start_node(
    launch_process: Any, ros_master: Any, name: str, topic: str, how: str, stale: str = ""
) -> Any:
    """A real rospy node ``name`` publishing ``topic``, once the master lists it.

    ``stale`` is a URI the master may still hold for ``name``: the new node has
    registered once the master holds another.
    """
    process = launch_process(
        [sys.executable, "-c", NODE_SCRIPT, name, topic, how],
        env=ros_master.env,
        name=name.strip("/").replace("/", "_"),
    )
    wait_until(
        lambda: (
            process.poll() is not None
            or (
                name in publishers(topic, ros_master)
                and registered_uri(name, ros_master) not in (None, stale)
            )
        ),
        START,
        f"{name} publishes {topic}",
    )
    assert process.poll() is None, process.log()
    return process


def leave_stale_registration(node: str, topic: str, uri: str, ros_master: Any) -> None:
    """What the master holds after ``node`` died with -9 and its port went to ``uri``'s owner."""
    master_of(node, ros_master).registerPublisher(topic, "std_msgs/String", uri)
    assert registered_uri(node, ros_master) == uri


def stranger_at(launch_process: Any, ros_master: Any, name: str) -> tuple[Any, str]:
    """A live node unrelated to the name under test, and its URI."""
    process = start_node(launch_process, ros_master, name, f"{name}/chatter", "plain")
    uri = registered_uri(name, ros_master)
    assert uri is not None
    return process, uri


def test_plain_init_node_shuts_down_the_process_that_took_the_old_port(
    ros_master: Any, launch_process: Any
) -> None:
    """The hazard itself: the master sends its shutdown to whoever has the stale URI now."""
    stranger, uri = stranger_at(launch_process, ros_master, "/stranger_a")
    leave_stale_registration("/respawned_a", "/respawned_a/events", uri, ros_master)

    start_node(launch_process, ros_master, "/respawned_a", "/respawned_a/events", "plain", uri)

    wait_until(lambda: stranger.poll() is not None, START, "the stranger was shut down")
    assert BUMPED in stranger.log()


def test_join_graph_forgets_the_stale_entry_and_leaves_the_stranger_running(
    ros_master: Any, launch_process: Any
) -> None:
    stranger, uri = stranger_at(launch_process, ros_master, "/stranger_b")
    leave_stale_registration("/respawned_b", "/respawned_b/events", uri, ros_master)

    assert clear_stale_registration("/respawned_b", master_of("/respawned_b", ros_master))
    # With no entry for the name, the master has no URI to send a shutdown to.
    assert registered_uri("/respawned_b", ros_master) is None
    assert publishers("/respawned_b/events", ros_master) == []

    leave_stale_registration("/respawned_b", "/respawned_b/events", uri, ros_master)
    respawned = start_node(
        launch_process, ros_master, "/respawned_b", "/respawned_b/events", "join_graph", uri
    )
    assert stranger.poll() is None and BUMPED not in stranger.log(), stranger.log()
    assert respawned.poll() is None


def test_a_dead_registration_with_services_and_parameters_is_removed_whole(
    ros_master: Any,
) -> None:
    node = "/respawned_c"
    dead_uri = f"http://127.0.0.1:{free_port()}/"
    master = master_of(node, ros_master)
    master.registerPublisher("/respawned_c/events", "std_msgs/String", dead_uri)
    master.registerSubscriber("/respawned_c/commands", "std_msgs/String", dead_uri)
    master.registerService(
        "/respawned_c/get_loggers", f"rosrpc://127.0.0.1:{free_port()}", dead_uri
    )
    master.subscribeParam(dead_uri, "/rosout_disable_topics_generation")

    assert clear_stale_registration(node, master)
    assert registered_uri(node, ros_master) is None


def test_a_live_node_of_the_same_name_is_still_replaced(
    ros_master: Any, launch_process: Any
) -> None:
    """The ROS rule stands: a second node of a name shuts the first one down."""
    first = start_node(launch_process, ros_master, "/twice", "/twice/events", "join_graph")
    assert not clear_stale_registration("/twice", master_of("/twice", ros_master))

    start_node(launch_process, ros_master, "/twice", "/twice/events", "join_graph")

    wait_until(lambda: first.poll() is not None, START, "the first node was replaced")
    assert BUMPED in first.log()


def test_a_respawned_mission_server_leaves_the_process_on_its_old_port_running(
    ros_master: Any, launch_process: Any, start_server: Any
) -> None:
    server_name = interface.SERVER_NODE
    stranger, uri = stranger_at(launch_process, ros_master, "/robot_side_node")
    leave_stale_registration(server_name, interface.EVENTS_TOPIC, uri, ros_master)

    start_server()

    assert registered_uri(server_name, ros_master) not in (None, uri)
    assert stranger.poll() is None and BUMPED not in stranger.log(), stranger.log()
