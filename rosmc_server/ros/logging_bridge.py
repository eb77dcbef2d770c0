"""Route the library's ``logging`` records to rosout, so operators see them in rqt_console."""

from __future__ import annotations

import logging

import rospy

_LEVELS = (
    (logging.CRITICAL, rospy.logfatal),
    (logging.ERROR, rospy.logerr),
    (logging.WARNING, rospy.logwarn),
    (logging.INFO, rospy.loginfo),
)


class RosoutHandler(logging.Handler):
    """A logging handler that forwards records to the rospy log functions."""

    def emit(self, record: logging.LogRecord) -> None:
        """Forward one record at its level."""
        message = self.format(record)
        for level, log in _LEVELS:
            if record.levelno >= level:
                log(message)
                return
        rospy.logdebug(message)


def bridge_logging_to_rosout(level: int = logging.INFO) -> None:
    """Forward the ``rosmc_*`` packages' log records to rosout (call after init_node)."""
    handler = RosoutHandler()
    handler.setFormatter(logging.Formatter("%(message)s"))
    for name in ("rosmc_server", "rosmc_sim", "rosmc_rviz_markers", "rosmc_rqt_command"):
        logger = logging.getLogger(name)
        logger.setLevel(level)
        logger.addHandler(handler)
        logger.propagate = False
