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
    # caller chose one. ROS_IP defaults to loopback unless the caller set ROS_IP or
    # ROS_HOSTNAME (for a team spread over several machines, set them before sourcing).
    if [[ -n "$had_master_uri" ]]; then
        export ROS_MASTER_URI="$had_master_uri"
    else
        export ROS_MASTER_URI="http://127.0.0.1:11311"
    fi
    if [[ -z "${ROS_IP:-}" && -z "${ROS_HOSTNAME:-}" ]]; then
        export ROS_IP="127.0.0.1"
    fi
    export ROSMC_ROOT="$root"
    return "$status"
}

# Run with the caller's -e/-u switched off (catkin's setup.bash and venv's activate are not
# written for them), then switch back on what the caller had on.
_rosmc_env_opts="$-"
set +eu
_rosmc_env_main
_rosmc_env_status=$?
if [[ "$_rosmc_env_opts" == *e* ]]; then set -e; fi
if [[ "$_rosmc_env_opts" == *u* ]]; then set -u; fi
unset -f _rosmc_env_main
unset _rosmc_env_opts
# The status is expanded before the unset runs. 1 means `make setup` has not run yet.
eval "unset _rosmc_env_status; return $_rosmc_env_status"
