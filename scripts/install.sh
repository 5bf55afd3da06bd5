#!/usr/bin/env bash
# Install nrtrans into a venv (./.venv unless --venv DIR) with the given extras,
# plus the Debian packages it needs: PortAudio for capture, PulseAudio and
# espeak-ng for the voice tests, and systemd-analyze for the unit checks.
#
#   scripts/install.sh                         the runtime (simulator backend)
#   scripts/install.sh ros                     + ROS 2 Kilted wheels from PyPI
#   scripts/install.sh ros-jazzy               + ROS 2 Jazzy wheels from PyPI
#   scripts/install.sh --venv .venv-jazzy test,ros-jazzy
#
# One venv holds one ROS 2 distribution: both ship the same Python modules.
set -euo pipefail
cd "$(dirname "$0")/.."
venv=.venv
if [[ "${1:-}" == "--venv" ]]; then
  venv=${2:?"--venv needs a directory"}
  shift 2
fi
extras="${1:-}"
IFS=, read -r -a extra_list <<<"$extras"
has_extra() {
  local wanted=$1 extra
  for extra in "${extra_list[@]}"; do [[ "$extra" == "$wanted" ]] && return 0; done
  return 1
}
if has_extra ros && has_extra ros-jazzy; then
  echo "nrtrans install: choose one ROS 2 distribution per venv: 'ros' (Kilted) or 'ros-jazzy' (Jazzy)" >&2
  exit 2
fi

apt_packages=(libportaudio2)
if has_extra test; then
  apt_packages+=(pulseaudio pulseaudio-utils libasound2-plugins espeak-ng systemd)
fi
missing=()
for package in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
done
if ((${#missing[@]})); then
  if [[ $(id -u) -eq 0 ]] && command -v apt-get >/dev/null; then
    echo "nrtrans install: apt-get install ${missing[*]}" >&2
    apt-get update -qq >/dev/null 2>&1 || true
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  else
    echo "nrtrans install: please install these Debian packages first: ${missing[*]}" >&2
    exit 1
  fi
fi

python=${PYTHON:-python3}
[[ -x "$venv/bin/python" ]] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
if has_extra train; then
  # The CPU build of torch must come first and stay pinned, or a later
  # requirement pulls several GB of CUDA wheels.
  "$venv/bin/pip" install -q torch==2.13.0
fi
echo "nrtrans install: pip install -e .${extras:+[$extras]} into $venv (the first build of llama-cpp-python takes ~4 minutes)" >&2
"$venv/bin/pip" install -q -e ".${extras:+[$extras]}"
