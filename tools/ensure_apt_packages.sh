#!/usr/bin/env bash
# Install the Debian packages given as arguments, but only those not installed yet.
# Runs `apt-get update` only when something must be installed. No TTY needed.
set -euo pipefail

# One dpkg-query for all of them; unknown names are simply absent from its output.
declare -A installed=()
while IFS=$'\t' read -r pkg status; do
    # "install ok installed" or "hold ok installed"; not "... config-files" / "half-installed"
    if [[ "$status" == *" ok installed" ]]; then installed["$pkg"]=1; fi
done < <(dpkg-query -W -f='${Package}\t${Status}\n' "$@" 2>/dev/null || true)

missing=()
for pkg in "$@"; do
    if [[ -z "${installed[$pkg]:-}" ]]; then missing+=("$pkg"); fi
done
if ((${#missing[@]} == 0)); then exit 0; fi

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
