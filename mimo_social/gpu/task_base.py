"""The protocol of the batched task logic (:mod:`mimo_social.gpu.tasks`): task logic for every
world at once, rewards, success, terminations and the task's infos, computed from the batched
device data (torch tensors) as the CPU task computes them from ``MjData``, with the task's
per-step state (a hold timer) as a per-world tensor.

Each class is made from the CPU env (``env``, the task bound to its world: the index tables
are read from it) and the :class:`~mimo_social.gpu.batched.BatchedEnv` made of it, and has:
* ``batch_fields``: the model fields its reset changes per world (reach: the ball's
  ``body_pos``), batched per world on the device;
* ``capture(env)``: what the task's reset drew on the CPU env just reset (host work at resets);
* ``load(idx, captured)``: that put into the worlds ``idx``, the per-world state reset
  (``captured``: the captures of those worlds stacked, each key's values ``(len(idx), ...)``,
  numpy or torch: :func:`~mimo_social.gpu.stacking.stack_rows`);
* ``before_physics()``: the task's per-step hook (reach: head and eyes on the ball);
* ``evaluate()``: ``(rewards (nworld, n_agents), terminated (nworld,), infos)``, infos a dict
  of the CPU task's info keys to ``(nworld,)`` tensors (``(nworld, n_agents)`` for per-agent
  ones), reading the step's data (positions and contacts of the last physics step's start, as
  the CPU task reads ``MjData`` after ``mj_step``);
* ``observed`` and ``observe()``: the task's own observation keys (self-body: the one-hot
  ``target``) and, per agent, a dict of them to ``(nworld, size)`` tensors, as the CPU task's
  ``observe`` gives them (new tensors: a later reset does not change what was returned).

:class:`BatchedTask` holds the defaults (no per-world fields, nothing captured, no hook, no
task observation).
"""

from __future__ import annotations

__all__ = ["BatchedTask", "hold_steps", "streak"]


def hold_steps(seconds: float, dt: float) -> int:
    """The control steps in a row a task's success must hold (at least 1), as the CPU tasks
    count them."""
    return max(1, round(float(seconds) / float(dt)))


def streak(count, on):
    """Per world, the steps in a row ``on`` has held: ``count + 1`` where it holds, else 0."""
    return (count + 1) * on


class BatchedTask:
    """The defaults of the batched task logic (the module's protocol)."""

    name = ""
    batch_fields: tuple[str, ...] = ()
    info_keys: tuple[str, ...] = ()
    per_agent_infos: tuple[str, ...] = ()
    observed: tuple[str, ...] = ()

    def __init__(self, env, batched):
        self.batched = batched
        self.n_agents = len(env.world.agents)

    def capture(self, env) -> dict:
        return {}

    def load(self, idx, captured) -> None:
        return None

    def before_physics(self) -> None:
        return None

    def observe(self) -> list[dict]:
        return [{} for _ in range(self.n_agents)]
