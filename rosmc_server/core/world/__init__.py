"""The site in the map frame: orientation math, area polygons,
the site map and which map is in force.

See :mod:`rosmc_server.core` for the order of the subpackages.
"""
