#!/usr/bin/env bash
# The GPU backend's figures in one run, for a machine with an NVIDIA GPU (docs/gpu.md,
# BENCHMARKS.md): agent-steps/s of two-infant high five at 1, 64, 1024 and 4096 worlds with and
# without touch, with both eyes at 64 x 64, with the task's logic and its resets (CPU resets and
# a bank of kept starts), and PPO learning high five for at most TRAIN_S seconds (its
# progress.csv has the success rate over wall time). Each part has its own time limit and
# writes its JSON or run folder under OUT, so a part that overruns leaves the others' figures.
#
#   bash scripts/gpu_figures.sh OUT            # at most 16 minutes: 5 x 2 min + TRAIN_S + 1 min
#   QUICK=1 bash scripts/gpu_figures.sh OUT    # a few worlds and steps: checks the commands
#
# It runs on Warp's CPU device too (and says so in every table), which is what QUICK is for.
set -uo pipefail
out=${1:?usage: bash scripts/gpu_figures.sh OUT}
mkdir -p "$out"
if [ "${QUICK:-0}" = 1 ]; then
  worlds=1,2; big=2; steps=2; train_worlds=2; train_steps=32; train_s=120; part_s=300
  train_args="--rollout 4 --minibatch 4 --epochs 1 --max-steps 4"
else
  worlds=1,64,1024,4096; big=4096; steps=100; train_worlds=4096; train_steps=20000000
  train_s=${TRAIN_S:-300}; part_s=120; train_args=""
fi
nvidia-smi -L > "$out/gpu.txt" 2>&1 || echo "no nvidia-smi: no NVIDIA GPU here" > "$out/gpu.txt"
status=0
part() {   # part NAME LIMIT_S COMMAND...: run with a time limit, note its exit status
  local name=$1 limit=$2
  shift 2
  echo "== $name (at most ${limit} s)"
  timeout "$limit" "$@" > "$out/$name.log" 2>&1
  local rc=$?
  echo "$name: exit $rc" | tee -a "$out/status.txt"
  tail -n 8 "$out/$name.log"
  # PPO stopped by its own time limit (SIGINT: 130) has done what it was for
  [ $rc -eq 0 ] || { [ "$name" = ppo_high_five ] && [ $rc -eq 130 ]; } || status=1
}
part bench "$part_s" mimo-social bench gpu --worlds "$worlds" --steps "$steps" \
  --json "$out/bench.json"
part bench_no_touch "$part_s" mimo-social bench gpu --worlds "$worlds" --steps "$steps" \
  --no-touch --json "$out/bench_no_touch.json"
part bench_eyes64 "$part_s" mimo-social bench gpu --worlds "$worlds" --steps "$steps" \
  --eyes 64 --json "$out/bench_eyes64.json"
part bench_task "$part_s" mimo-social bench gpu --worlds "$big" --steps "$steps" --with-task \
  --json "$out/bench_task.json"
part bench_task_bank "$part_s" mimo-social bench gpu --worlds "$big" --steps "$steps" \
  --with-task --reset-bank "$big" --json "$out/bench_task_bank.json"
# PPO: stopped at TRAIN_S seconds whatever its step budget; progress.csv is written as it goes
# shellcheck disable=SC2086
part ppo_high_five "$((train_s + 60))" timeout --signal=INT "$train_s" \
  mimo-social train-gpu --task high_five --worlds "$train_worlds" --steps "$train_steps" \
  --out "$out/ppo_high_five" $train_args
exit $status
