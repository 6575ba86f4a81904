"""Free play: infants stand on a floor facing each other; no reward, no end but the time limit.

agents:
    1-8 (default 2; the Gymnasium id: 1), `infant_0` ... on a circle around the origin, each facing
    the centre (the circle leaves room for the largest agent's reach)
body:
    free base; standing by default (`posture="sitting"` or `"lying"` too); every joint free, every
    motor in the action; mitten hands and spring-damper motors by default
scene:
    the floor; with `props=True` a ball (r = 4 cm) and a cube (6 cm) lie between the infants
reset:
    the initial pose; nothing random in the task
action:
    every motor: 44 in [-1, 1] (mitten hands), plus the expression (`Discrete(7)`) while expressions
    are on (default)
observation:
    `proprioception` (276), `vestibular` (6); other senses on request (`touch=...`, `vision=...`)
reward:
    0
success:
    none
termination:
    none; truncation at 1000 steps
options:
    `props` (False)
privileged cues:
    none
baselines:
    no reward, so no learning baseline; its speed (the scene of the benchmarks) is measured by
    `mimo-social bench sim` (BENCHMARKS.md)
sources:
    not in the MIMo paper as a task: the sandbox of this package
version history:
    v0: first version, with the first env

``parallel_env(n_agents=..., task_options={...}, physics={...}, per_agent=[...], **agent_settings)``
returns a :class:`~mimo_social.core.env.MimoParallelEnv`; ``env(...)`` the AEC version.
"""

from .task import (parallel_env, env, FreePlay, FreePlayOptions)

__all__ = ["parallel_env", "env", "FreePlay", "FreePlayOptions"]
