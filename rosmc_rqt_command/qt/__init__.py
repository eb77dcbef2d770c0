"""The command GUI's Qt models and widgets (no rospy: the ROS bridge feeds them)."""
