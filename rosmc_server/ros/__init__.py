"""ROS adapters of the mission server, and its client (``client/``): the rospy users.

Messages become core objects only in :mod:`rosmc_server.conversions`, below this layer.
"""
