# shellcheck shell=bash
# The ROSMC development environment. Source it from bash, from any directory:
#
#     source env.sh
#
# Afterwards the venv's python comes first on PATH, the generated messages import
# (`import rosmc.msg`), the rosmc_* packages import from this checkout, the entry scripts
# in scripts/ are commands, and `rosrun rosmc ...` / `roslaunch rosmc ...` find this package.
# `make setup` creates everything this file expects. Sourcing it twice is harmless, and it
# never changes the caller's shell options (no `set -e` leaks out).

_rosmc_env_main() {
    local root venv devel had_master_uri status=0
    root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
    venv="$root/.venv"
    devel="$root/build/devel"
    had_master_uri="${ROS_MASTER_URI:-}"

    # Remove every occurrence of $2 from the ':'-list in variable $1, then put it in front.
    _rosmc_prepend() {
        local name="$1" dir="$2" list
        list=":${!name:-}:"
        while [[ "$list" == *":$dir:"* ]]; do
            list="${list//:"$dir":/:}"
        done
        list="${list#:}"
        list="${list%:}"
        printf -v "$name" '%s' "$dir${list:+:$list}"
        export "${name?}"
    }

    # The catkin devel space of the standalone build: rosmc.msg / rosmc.srv on PYTHONPATH,
    # this package on ROS_PACKAGE_PATH and CMAKE_PREFIX_PATH (what rosrun/roslaunch search).
    if [[ -f "$devel/setup.bash" ]]; then
        # shellcheck disable=SC1091
        source "$devel/setup.bash"
    else
        echo "env.sh: $devel/setup.bash is missing; run 'make setup' first" >&2
        status=1
    fi

    if [[ -x "$venv/bin/python" ]]; then
        # shellcheck disable=SC1091
        source "$venv/bin/activate"
        # Devel-space relays (what rosrun and roslaunch start) run /usr/bin/python3, the
        # interpreter the venv was made from, which does not see the venv by itself. Making
        # the venv its user base puts the venv's site-packages exactly where the venv python
        # has them: after the standard library, before Debian's dist-packages.
        export PYTHONUSERBASE="$venv"
    else
        echo "env.sh: $venv is missing; run 'make setup' first" >&2
        status=1
    fi

    _rosmc_prepend PYTHONPATH "$root"
    _rosmc_prepend PATH "$root/scripts"
    unset -f _rosmc_prepend

    # Devel setup.bash defaults the master to localhost; ours is explicit loopback unless the
    # caller chose one. Unless the caller set ROS_IP or ROS_HOSTNAME, ROS_IP is loopback for
    # a master on this machine and, for a master on another machine, this machine's address
    # on the way there: nodes advertise it, and the other machines connect to it (loopback
    # there would send every peer to itself).
    if [[ -n "$had_master_uri" ]]; then
        export ROS_MASTER_URI="$had_master_uri"
    else
        export ROS_MASTER_URI="http://127.0.0.1:11311"
    fi
    if [[ -z "${ROS_IP:-}" && -z "${ROS_HOSTNAME:-}" ]]; then
        _rosmc_default_ros_ip
    fi
    export ROSMC_ROOT="$root"
    return "$status"
}

# Set ROS_IP for ROS_MASTER_URI's host: 127.0.0.1 for a loopback master, else the source
# address of this machine's route to it. Without a route it says what to do and sets nothing.
_rosmc_default_ros_ip() {
    local host address src
    host="${ROS_MASTER_URI#*://}"
    host="${host%%/*}"
    host="${host%:*}"
    case "$host" in
        localhost | 127.*) address="127.0.0.1" ;;
        *) address="$(getent ahostsv4 "$host" 2>/dev/null | awk 'NR == 1 { print $1 }')" ;;
    esac
    if [[ "$address" == 127.* ]]; then
        export ROS_IP="127.0.0.1"
        return 0
    fi
    if [[ -n "$address" ]]; then
        src="$(ip -4 -o route get "$address" 2>/dev/null |
            sed -n 's/.* src \([0-9.]*\).*/\1/p')"
    fi
    if [[ -z "${src:-}" ]]; then
        echo "env.sh: no address of this machine towards the master's host '$host'" \
            "(ROS_MASTER_URI); set ROS_IP to the address the other machines reach" >&2
        return 0
    fi
    export ROS_IP="$src"
}

# Run with the caller's -e/-u switched off (catkin's setup.bash and venv's activate are not
# written for them), then switch back on what the caller had on.
_rosmc_env_opts="$-"
set +eu
_rosmc_env_main
_rosmc_env_status=$?
if [[ "$_rosmc_env_opts" == *e* ]]; then set -e; fi
if [[ "$_rosmc_env_opts" == *u* ]]; then set -u; fi
unset -f _rosmc_env_main _rosmc_default_ros_ip
unset _rosmc_env_opts
# The status is expanded before the unset runs. 1 means `make setup` has not run yet.
eval "unset _rosmc_env_status; return $_rosmc_env_status"
