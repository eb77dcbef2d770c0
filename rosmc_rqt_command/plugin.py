"""The command GUI as an rqt plugin (where rqt is installed; it is not packaged in Debian).

A thin wrapper: it builds the same widget and bridge as the standalone window and
forwards rqt's lifecycle calls. Importing this module without rqt still works (the
plugin class then derives from ``object`` and is never loaded by anyone).
"""

from __future__ import annotations

from typing import Any

from rosmc_server.ros.client import init_node

from .standalone import build

try:
    from qt_gui.plugin import Plugin as _RqtPlugin  # type: ignore[import-not-found]
except ImportError:  # no rqt here: the module still imports
    _RqtPlugin = object


class CommandPlugin(_RqtPlugin):  # type: ignore[misc]
    """ROSMC / Command GUI in rqt's plugin menu."""

    def __init__(self, context: Any) -> None:
        super().__init__(context)
        self.setObjectName("RosmcCommand")
        init_node()  # rqt_gui_py made the process a node already; this keeps the call harmless
        self._widget, self._bridge = build()
        if context.serial_number() > 1:
            self._widget.setWindowTitle(f"ROSMC command ({context.serial_number()})")
        context.add_widget(self._widget)

    def shutdown_plugin(self) -> None:
        """Stop following the mission and calling the server."""
        self._widget.replay.close()
        self._bridge.close()

    def save_settings(self, plugin_settings: Any, instance_settings: Any) -> None:
        """Nothing to keep: the mission lives on the server."""

    def restore_settings(self, plugin_settings: Any, instance_settings: Any) -> None:
        """Nothing to restore."""
