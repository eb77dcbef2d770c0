#!/usr/bin/env bash
# Print rosdep's sources-list lines for this checkout's rosdep rules, e.g.
#
#     rosdep/sources.sh | sudo tee /etc/ros/rosdep/sources.list.d/30-rosmc.list && rosdep update
#
# rosmc.yaml holds keys rosdistro lacks; debian.yaml is read on Debian only (tag `debian`).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
echo "yaml file://$here/rosmc.yaml"
echo "yaml file://$here/debian.yaml debian"
