"""The robot link free of ROS: protocol, liveness, the signed radio, commands that wait,
robots' live status.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
