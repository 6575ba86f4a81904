#!/usr/bin/env bash
# RLlib (Ray) for `mimo-social train --engine rllib` and `compare --engine rllib`, in a second
# virtual environment: ray[rllib] 2.60.0 pins gymnasium 1.2.2, older than the main environment's.
# `.venv-rllib` sees the main environment's packages (torch, mimo_social installed by
# scripts/setup.sh) and adds ray with its own gymnasium on top. Safe to run again.
# Then: .venv-rllib/bin/mimo-social train --engine rllib ...   (tests: scripts/test_rllib.sh)
set -euo pipefail
cd "$(dirname "$0")/.."

PY=${PYTHON:-python3}
VENV=${RLLIB_VENV:-.venv-rllib}
RAY="ray[rllib]==2.60.0"

if [ ! -x "$VENV/bin/python" ]; then
  echo "[setup_rllib] making $VENV (with the system site packages)"
  $PY -m venv --system-site-packages "$VENV"
fi
if ! "$VENV/bin/python" -c "import ray, ray.rllib; assert ray.__version__ == '2.60.0'" \
    >/dev/null 2>&1; then
  echo "[setup_rllib] installing $RAY into $VENV"
  "$VENV/bin/python" -m pip install -q "$RAY"
fi
if ! "$VENV/bin/python" -c "import mimo_social" >/dev/null 2>&1; then
  echo "[setup_rllib] mimo_social is not importable from $VENV: install it in the main" \
    "environment first (scripts/setup.sh), with the same $PY" >&2
  exit 1
fi
if [ ! -x "$VENV/bin/mimo-social" ]; then   # the command, run with this venv's python
  echo "[setup_rllib] adding $VENV/bin/mimo-social"
  printf '#!/bin/sh\nexec "$(dirname "$0")/python" -m mimo_social.cli "$@"\n' \
    > "$VENV/bin/mimo-social"
  chmod +x "$VENV/bin/mimo-social"
fi
"$VENV/bin/python" -c "import ray, gymnasium; print('[setup_rllib] ray', ray.__version__, \
'gymnasium', gymnasium.__version__)"
echo "[setup_rllib] done"
