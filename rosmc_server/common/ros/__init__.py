"""ROS helpers of every ROSMC node, ground or robot: the radio side channel
(:mod:`.radio`), where a launched node's relative paths point (:mod:`.station`), logging to
rosout (:mod:`.logging_bridge`) and connection checks (:mod:`.connections`)."""
