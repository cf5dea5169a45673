# shellcheck shell=bash
# Installation of Debian packages, sourced by tools/quickstart.sh and .ci/run.

# ensure_packages PKG...: install the packages that are not installed yet with apt-get, as root
# directly or else through sudo. Runs `apt-get update` only when something must be installed, so
# it costs a dpkg-query on a prepared machine.
ensure_packages() {
    local missing=() pkg status
    if ! command -v dpkg-query >/dev/null 2>&1; then
        echo "No dpkg-query: not a Debian system. Make sure these are installed: $*" >&2
        return 0
    fi
    for pkg in "$@"; do
        status=$(dpkg-query -W -f='${db:Status-Abbrev}' "$pkg" 2>/dev/null || true)
        if [[ $status != ii* ]]; then
            missing+=("$pkg")
        fi
    done
    if ((${#missing[@]} == 0)); then
        echo "Packages: all present ($*)"
        return 0
    fi
    local sudo=()
    if ((EUID != 0)); then
        if ! command -v sudo >/dev/null 2>&1; then
            echo "Missing packages: ${missing[*]}; not root and no sudo: install them, then re-run." >&2
            return 1
        fi
        sudo=(sudo)
    fi
    echo "Packages: installing ${missing[*]}"
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
    # Recommends stay on: gcc needs libc6-dev from them, valgrind libc6-dbg.
    "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -q -y "${missing[@]}"
}
