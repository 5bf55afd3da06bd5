#!/usr/bin/env bash
# Install nrtrans into ./.venv with the given extras (e.g. `test`), plus the
# Debian packages it needs: PortAudio for capture, PulseAudio and espeak-ng
# for the voice tests, and systemd-analyze for the unit checks.
set -euo pipefail
cd "$(dirname "$0")/.."
extras="${1:-}"

apt_packages=(libportaudio2)
if [[ "$extras" == *test* ]]; then
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
[[ -x .venv/bin/python ]] || "$python" -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
if [[ "$extras" == *train* ]]; then
  # The CPU build of torch must come first and stay pinned, or a later
  # requirement pulls several GB of CUDA wheels.
  .venv/bin/pip install -q torch==2.13.0
fi
echo "nrtrans install: pip install -e .${extras:+[$extras]} (the first build of llama-cpp-python takes ~4 minutes)" >&2
.venv/bin/pip install -q -e ".${extras:+[$extras]}"
