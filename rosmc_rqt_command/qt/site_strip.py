"""The site line under the science strip: which site map the mission checks targets against.

Fed from ``/rosmc/site_in_force`` by the ROS bridge (as a core
:class:`~rosmc_server.core.world.site_source.SiteInForce`, None before a map is in force): the
map's name, the node that sent it and when. ROS 1 lets any node publish a map, so the
operator should see whose map is in force.
"""

from __future__ import annotations

from python_qt_binding.QtWidgets import QLabel, QWidget

from rosmc_server.core.world.site_source import NO_SITE, SiteInForce, site_line

from .labels import never_widen

_TIP = (
    "The mission server checks skill targets against the newest sane map on /rosmc/site; "
    "a map with impossible numbers or too many obstacles is refused (see the server log)."
)


class SiteStrip(QLabel):  # type: ignore[misc]
    """One small line saying which site map is in force, from which node, since when."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("site")
        never_widen(self)
        self.setStyleSheet("QLabel#site { color:#444; font-size:small; padding:0 3px; }")
        self.setToolTip(_TIP)
        self.source: SiteInForce | None = None
        self.setText(NO_SITE)

    def show_site(self, source: SiteInForce | None) -> None:
        """Show the map in force (None: none yet)."""
        self.source = source
        self.setText(site_line(source))
