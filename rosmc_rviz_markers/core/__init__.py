"""Pure marker logic: geometry, styling, menus, icons and requests (no rospy, no messages)."""
