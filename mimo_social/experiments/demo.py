"""The demo: infants face to face in free play, recorded to a Rerun ``.rrd`` file.

Every motor follows the package's smooth random actions
(:func:`mimo_social.core.random_actions.smooth_random_actions`, built as one block for the whole
run before it starts), and each infant changes its facial expression on average every
:data:`EXPRESSION_PERIOD` simulated seconds. The run is recorded with
:class:`mimo_social.recording.recorder.Recorder`; open the file with ``rerun FILE.rrd``. The
command is :mod:`mimo_social.cli.demo`.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from tqdm import tqdm

from ..core.random_actions import random_action_block
from ..envs import free_play_v0
from ..recording.recorder import Recorder
from ..util.checks import check_int, check_number

__all__ = ["DEFAULT_RECORDING", "EXPRESSION_PERIOD", "MOTOR_TAU", "DemoRun", "demo_actions",
           "record_demo"]

DEFAULT_RECORDING = "recordings/demo.rrd"
#: mean simulated seconds between two expression changes of an infant
EXPRESSION_PERIOD = 1.5
#: time constant (s) of the motors' low-pass filters: slow, smooth movements
MOTOR_TAU = 0.3


@dataclass(frozen=True)
class DemoRun:
    """What :func:`record_demo` wrote: the file, the steps run, the simulated seconds, the
    number of infants, why the episode stopped early (None when it ran to the end)."""

    path: Path
    steps: int
    seconds: float
    n_agents: int
    stopped: str | None


def demo_actions(env, n_steps: int, seed: int) -> list[dict]:
    """The action dict of every step of the run (seeded, smooth, expressions every
    :data:`EXPRESSION_PERIOD` seconds on average)."""
    return random_action_block(env, n_steps, seed, tau=MOTOR_TAU,
                               expression_period=EXPRESSION_PERIOD)


def record_demo(path: str | Path = DEFAULT_RECORDING, seconds: float = 10.0, n_agents: int = 2,
                seed: int = 0, progress: bool = True) -> DemoRun:
    """Run ``n_agents`` infants (1 to 8) in free play for ``seconds`` simulated seconds and
    record the run to ``path`` (its folder is created)."""
    seconds = check_number("demo", "seconds", seconds, 0.0)   # at least one step is run
    check_int("demo", "n_agents", n_agents, 1, 8)
    path = Path(path)
    env = free_play_v0.parallel_env(n_agents=n_agents, max_steps=10**9)
    try:
        steps = max(1, round(seconds / env.dt))
        block = demo_actions(env, steps, seed)
        env.reset(seed=seed)
        done = 0
        stopped = None
        with Recorder(env, path, recording_name=f"mimo-social demo (seed {seed})") as rec:
            rec.log_reset()
            for k in tqdm(range(steps), desc="demo", unit="step", disable=not progress):
                actions = {a: u for a, u in block[k].items() if a in env.agents}
                _, rewards, _, _, infos = env.step(actions)
                rec.log_step(actions, rewards)
                done = k + 1
                if not env.agents:
                    stopped = next((info.get("instability") for info in infos.values()
                                    if info.get("instability")), "every agent is done")
                    break
        return DemoRun(path, done, done * env.dt, n_agents, stopped)
    finally:
        env.close()
