"""The rospy side of the marker node: interactive-marker server adapter, conversions, node."""
