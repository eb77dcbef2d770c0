"""ROS adapters of the simulation."""
