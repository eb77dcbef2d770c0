"""What the guides say where they start, for a lab with robots on other machines.

Checked in the text, since no test can start a second machine's shell: ``ROS_IP`` is set by
hand on every machine (the ground too, or it restarts), and in a workspace shell the
``rosmc`` command is reached through rosrun.
"""

from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def opening(path: str, heading: str) -> str:
    """The text of ``path`` from its start to the end of the section ``heading``."""
    text = (REPO / path).read_text()
    start = text.index(heading)
    following = text.find("\n## ", start + len(heading))
    return text[: following if following >= 0 else len(text)]


def test_the_readme_and_the_integrator_guide_say_ros_ip_before_anything_starts() -> None:
    for path, heading in (
        ("README.md", "source env.sh"),
        ("docs/integrator-guide.md", "## Running the nodes"),
    ):
        text = " ".join(opening(path, heading).split()).lower()
        text = text.replace("`ros_master_uri` and ", "")
        assert "set `ros_ip` by hand on every machine" in text, path
        assert "127.0.0.1" in text, path
        assert "restart" in text or "start them again" in text, path


def test_a_workspace_shell_is_told_to_use_rosrun() -> None:
    for path in ("README.md", "docs/integrator-guide.md", "docs/workspace.md"):
        assert "rosrun rosmc rosmc" in (REPO / path).read_text(), path
