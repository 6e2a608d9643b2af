#!/usr/bin/env bash
# Installs everything lerobot-phantom needs on a fresh Debian machine with Python 3.11:
# system packages (ffmpeg for video decoding, Mesa EGL/OSMesa for offscreen MuJoCo rendering), then the package
# with its test extra. Safe to run twice.
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if command -v apt-get >/dev/null 2>&1; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
    ffmpeg libegl1 libegl-mesa0 libgl1 libgles2 libosmesa6 >/dev/null
fi

PYTHON="${PYTHON:-python3}"
"$PYTHON" -m pip install --quiet --upgrade pip
"$PYTHON" -m pip install --quiet -e ".[dev]"
echo "lerobot-phantom installed: $("$PYTHON" -c 'import lerobot_phantom, lerobot; print(lerobot_phantom.__version__, "on lerobot", lerobot.__version__)')"
