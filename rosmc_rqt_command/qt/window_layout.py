"""Where the command window's parts sit: menus, banner, tasks on the left, panels right."""

from __future__ import annotations

from dataclasses import dataclass

from python_qt_binding.QtCore import Qt
from python_qt_binding.QtWidgets import (
    QApplication,
    QLabel,
    QMenuBar,
    QSplitter,
    QVBoxLayout,
    QWidget,
)

from ..core.station_layout import Rect, split_screen
from .actions import CommandActions
from .control_panel import ControlPanel
from .labels import never_widen
from .legend import StatusLegend
from .message_area import MessageArea
from .parameter_panel import ParameterPanel
from .science_strip import ScienceStrip
from .site_strip import SiteStrip
from .task_widget import TaskWidget
from .team_bar import TeamBar
from .undo_history import UndoHistory

FILE_ITEMS = ("new", "open", "open_server", None, "save", "save_as", "save_server")
BANNER_STYLE = "QLabel { background:#fde2e1; color:#8a0010; padding:4px; }"
# The right-hand panels (parameters, control, messages) keep this width range: never so
# narrow that an editor is cut, never wider than they need (the tasks take the rest).
RIGHT_MIN_WIDTH = 330
RIGHT_MAX_WIDTH = 460


@dataclass(frozen=True)
class Panels:
    """The window's parts that the layout places (made by the window)."""

    actions: CommandActions
    history: UndoHistory
    tasks: TaskWidget
    team: TeamBar
    parameters: ParameterPanel
    control: ControlPanel
    messages: MessageArea


@dataclass(frozen=True)
class Layout:
    """What the layout made around the panels."""

    menu_bar: QMenuBar
    banner: QLabel
    science: ScienceStrip
    site: SiteStrip
    legend: StatusLegend
    splitter: QSplitter


def lay_out(window: QWidget, panels: Panels) -> Layout:
    """Place ``panels`` in ``window`` under a menu bar and a banner."""
    menu_bar = _menus(window, panels)
    banner = QLabel()
    banner.setObjectName("banner")
    never_widen(banner)
    banner.setStyleSheet(BANNER_STYLE)
    right = QSplitter(Qt.Vertical)
    for panel in (panels.parameters, panels.control, panels.messages):
        right.addWidget(panel)
    right.setStretchFactor(0, 3)
    right.setStretchFactor(2, 1)
    right.setMinimumWidth(RIGHT_MIN_WIDTH)
    right.setMaximumWidth(RIGHT_MAX_WIDTH)
    science, site, legend = ScienceStrip(), SiteStrip(), StatusLegend()
    left = QWidget()
    left_layout = QVBoxLayout(left)
    left_layout.setContentsMargins(0, 0, 0, 0)
    left_layout.setSpacing(2)
    for widget, stretch in ((science, 0), (site, 0), (panels.team, 0), (panels.tasks, 1)):
        left_layout.addWidget(widget, stretch)
    left_layout.addWidget(legend)
    splitter = QSplitter(Qt.Horizontal)
    splitter.addWidget(left)
    splitter.addWidget(right)
    splitter.setStretchFactor(0, 1)
    splitter.setStretchFactor(1, 0)
    # Neither side can be dragged away: a collapsed parameter panel took edits nowhere.
    splitter.setChildrenCollapsible(False)
    splitter.setSizes([1200, RIGHT_MIN_WIDTH])
    layout = QVBoxLayout(window)
    layout.setContentsMargins(2, 2, 2, 2)
    layout.setMenuBar(menu_bar)
    layout.addWidget(banner)
    layout.addWidget(splitter, 1)
    return Layout(menu_bar, banner, science, site, legend, splitter)


def _menus(window: QWidget, panels: Panels) -> QMenuBar:
    actions = panels.actions
    menu_bar = QMenuBar(window)
    file_menu = menu_bar.addMenu("&File")
    for name in FILE_ITEMS:
        if name is None:
            file_menu.addSeparator()
        else:
            file_menu.addAction(actions.file[name])
    menu_bar.addMenu("&Edit").addActions([panels.history.undo_action, panels.history.redo_action])
    mission_menu = menu_bar.addMenu("&Mission")
    mission_menu.addActions(list(actions.skill.values()))
    mission_menu.addSeparator()
    mission_menu.addActions(list(actions.all_robots.values()))
    mission_menu.addSeparator()
    mission_menu.addAction(actions.refresh)
    mission_menu.addAction(actions.clear_selection)
    return menu_bar


def place_on_screen(window: QWidget) -> None:
    """Put ``window`` on its share of the screen: the right part, beside rviz on the left.

    The share follows the screen's available area (without the desktop's panels), see
    :func:`~..core.station_layout.split_screen`.
    """
    screen = QApplication.primaryScreen()
    if screen is None:  # no screen at all (a headless platform without one)
        window.resize(760, 940)
        return
    area = screen.availableGeometry()
    place = split_screen(Rect(area.x(), area.y(), area.width(), area.height())).command
    window.setGeometry(place.x, place.y, place.width, place.height)
