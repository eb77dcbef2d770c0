#!/usr/bin/env bash
# Install the Debian packages given as arguments, but only those not installed yet.
# Runs `apt-get update` only when something must be installed. No TTY needed.
set -euo pipefail

missing=()
for pkg in "$@"; do
    status="$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)"
    # "install ok installed" or "hold ok installed"; not "... config-files" / "half-installed"
    [[ "$status" == *" ok installed" ]] || missing+=("$pkg")
done
((${#missing[@]} == 0)) && exit 0

sudo=()
if ((EUID != 0)); then
    if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
        sudo=(sudo -n)
    else
        echo "Missing Debian packages: ${missing[*]}" >&2
        echo "Install them as root: apt-get update && apt-get install -y ${missing[*]}" >&2
        exit 1
    fi
fi

echo "Installing Debian packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq "${missing[@]}"
