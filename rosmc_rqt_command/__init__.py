"""ROSMC command GUI: a Qt-free ``core/``, Qt widgets in ``qt/``, the ROS bridge, rqt plugin
and standalone window."""
