#!/usr/bin/env bash
# Run a command against a rosdep database built from local files only, for machines that
# cannot reach rosdistro (CI):
#
#     tools/rosdep_offline.sh DIR COMMAND [ARG...]
#
# DIR receives the sources list (Debian's ROS rules, tools/rosdistro_excerpt.yaml for the
# rosdistro keys package.xml uses, and rosdep/ as rosdep/sources.sh lists it), an empty
# rosdistro index and rosdep's cache; COMMAND then runs with ROSDEP_SOURCE_PATH,
# ROSDISTRO_INDEX_URL and ROS_HOME pointing there (rosdep, catkin_lint, ...).
set -euo pipefail
if [[ $# -lt 2 ]]; then
    echo "usage: $0 DIR COMMAND [ARG...]" >&2
    exit 2
fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dir="$(mkdir -p "$1" && cd "$1" && pwd)"
shift
sources="$dir/sources.list.d"
rm -rf "$sources"
mkdir -p "$sources"
if [[ -f /usr/share/python3-rosdep2/debian.yaml ]]; then
    echo "yaml file:///usr/share/python3-rosdep2/debian.yaml debian" > "$sources/10-debian.list"
fi
echo "yaml file://$root/tools/rosdistro_excerpt.yaml" > "$sources/20-rosdistro.list"
"$root/rosdep/sources.sh" > "$sources/30-rosmc.list"
printf 'distributions: {}\ntype: index\nversion: 4\n' > "$dir/index-v4.yaml"

export ROSDEP_SOURCE_PATH="$sources"
export ROSDISTRO_INDEX_URL="file://$dir/index-v4.yaml"
export ROS_HOME="$dir/home"
# rosdep warns about running as root on every call; the database is private to DIR.
rosdep update > "$dir/update.log" 2>&1 || { cat "$dir/update.log" >&2; exit 1; }
exec "$@"
