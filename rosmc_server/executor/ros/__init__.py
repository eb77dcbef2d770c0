"""ROS adapter of the mission executor."""
