"""ROS adapters of the mission server: the only place that imports rospy and messages."""
