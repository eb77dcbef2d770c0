"""What the ground station and the robots' executors both run, beyond the core.

The executor is the robot's and imports nothing of the ground (``rosmc_server.ros``); the
ground imports nothing of the executor. What both need of ROS lives in :mod:`.ros`.
"""
