#!/usr/bin/env bash
# Install everything mimo_social needs on a fresh Debian/Ubuntu machine with Python >= 3.11:
# Mesa's headless OpenGL (EGL, OSMesa) for rendering, the CPU build of torch, and the package
# with its training, development and documentation extras. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

PY=${PYTHON:-python3}
# chromium: the headless-browser check of a replay (scripts/check_viewer.py, driven by playwright)
DEBS="libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 libosmesa6 libglu1-mesa chromium"

missing=""
for p in $DEBS; do
  dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "[setup] installing Debian packages:$missing"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi

# torch first and pinned: an unpinned torch pulls a multi-GB CUDA build.
if ! $PY -c "import torch" >/dev/null 2>&1; then
  echo "[setup] installing torch==2.13.0 (CPU build)"
  $PY -m pip install -q "torch==2.13.0"
fi
echo "[setup] installing mimo-social with its train, dev, docs and gpu extras"
$PY -m pip install -q -e ".[train,dev,docs,gpu]"
echo "[setup] done"
