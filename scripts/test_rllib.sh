#!/usr/bin/env bash
# The RLlib tests (a Ray cluster on loopback, RLlib training, eval of its checkpoints, Tune
# trials, RLlib's PettingZoo wrapper on every env) in .venv-rllib (scripts/setup_rllib.sh
# makes it). Extra arguments go to pytest.
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=${RLLIB_VENV:-.venv-rllib}
if [ ! -x "$VENV/bin/python" ]; then
  echo "[test_rllib] no $VENV: run scripts/setup_rllib.sh first" >&2
  exit 1
fi
# the tests must not skip for want of ray here
"$VENV/bin/python" -c "import ray.rllib" || { echo "[test_rllib] ray[rllib] missing in $VENV" >&2; exit 1; }
exec "$VENV/bin/python" -m pytest -q -p no:cacheprovider \
  tests/train/test_rllib*.py tests/clients/test_rllib.py "$@"
