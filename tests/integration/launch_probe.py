"""Print, as JSON, what roslaunch would start for one launch file, without starting anything.

Run with Debian's python in a workspace's environment (``source install/setup.bash``):

    /usr/bin/python3 launch_probe.py PACKAGE FILE.launch [ARG:=VALUE ...]

Prints ``{"files": [...], "nodes": {name: argv}, "params": {name: value}}``: every launch file
read (includes too), each node's full command line as roslaunch builds it (which finds the
node's executable, so a missing one fails here), and every parameter it would set.
Imports only roslaunch, so the workspace under test is all that ``$(find ...)`` sees.
"""

from __future__ import annotations

import json
import sys

import roslaunch.config
import roslaunch.core
import roslaunch.node_args
import roslaunch.rlutil
import roslaunch.xmlloader


def probe(package: str, launch_file: str, args: list[str]) -> dict[str, object]:
    """Load the launch file as ``roslaunch PACKAGE FILE ARGS`` would, and describe it."""
    (path,) = roslaunch.rlutil.resolve_launch_arguments([package, launch_file])
    loader = roslaunch.xmlloader.XmlLoader(resolve_anon=False)
    config = roslaunch.config.load_config_default(
        [(path, [path, *args])], None, loader=loader, assign_machines=False
    )
    machine = roslaunch.core.local_machine()
    nodes = {
        f"{node.namespace}{node.name}": roslaunch.node_args.create_local_process_args(node, machine)
        for node in config.nodes
    }
    params = {name: param.value for name, param in config.params.items()}
    return {"files": sorted(config.roslaunch_files), "nodes": nodes, "params": params}


if __name__ == "__main__":
    print(json.dumps(probe(sys.argv[1], sys.argv[2], sys.argv[3:]), default=str))
