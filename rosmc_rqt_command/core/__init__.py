"""The command GUI without Qt or ROS: view state, legality views, requests, phrasing."""
