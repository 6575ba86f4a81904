"""``mimo-social bench gpu``: agent-steps per second of two-infant high five on MuJoCo Warp
(:class:`mimo_social.gpu.BatchedEnv`) at several numbers of worlds, on a GPU when Warp sees one,
else on Warp's CPU device (and it says so).

For each number of worlds: the batched env is built from ``high_five_v0.parallel_env()`` (two
infants, the task's defaults), reset, stepped ``warmup`` control steps (kernel loading, and on a
GPU the capture of the CUDA graph), then ``steps`` control steps are timed on the wall clock
with the device synchronised at both ends. Each step draws every agent's actions uniformly in
[-1, 1] on the device, maps them to controls, advances ``frame_skip`` physics steps and reads
every agent's proprioception, vestibular sense and hand skin (the task's default touch;
``touch=False`` / ``--no-touch`` leaves the skin out): what a learner on the device pays per
step.
With ``with_task=True`` (``mimo-social bench gpu --with-task``) the worlds are a
:class:`~mimo_social.gpu.BatchedTaskEnv`: the task's rewards, success and terminations on the
device too, and the finished worlds reset from their seeds' CPU resets (host work, counted in
the time; ``resets``: how many). Agent-steps per second: worlds x agents x steps / seconds.
"""

from __future__ import annotations

import time

from ..bench.machine import machine_info
from ..envs import high_five_v0
from ..gpu import BatchedEnv, BatchedTaskEnv, describe, pick_device, require

__all__ = ["WORLDS", "measure", "measure_one", "format_results"]

#: the numbers of worlds of the issue's benchmark (issue 34)
WORLDS = (1, 64, 1024, 4096)


def measure_one(nworld: int, steps: int, warmup: int = 2, device: str | None = None,
                make_env=None, with_task: bool = False, touch: bool = True,
                reset_bank: int | None = None, eyes: int | None = None) -> dict:
    """One number of worlds: build, warm up, time ``steps`` control steps (see the module);
    with the task, then one reset of every world, timed (``reset_ms_per_world``; from the
    ``reset_bank`` when given, else a CPU reset per world). ``eyes``: every agent's two eyes
    rendered each step, ``eyes`` x ``eyes`` pixels (the default env's vision; None: no eyes)."""
    _, _, torch = require()
    t0 = time.perf_counter()
    if make_env is None:
        kw = {} if eyes is None else {"vision": {"width": int(eyes), "height": int(eyes)}}
        env = high_five_v0.parallel_env(**kw)
    else:
        env = make_env()
    if with_task:
        tenv = BatchedTaskEnv(env, nworld, device=device, seed=0, touch=touch,
                              reset_bank=reset_bank)
        tenv.reset()
        batched = tenv.batched
    else:
        batched = BatchedEnv(env, nworld, device=device, seed=0, touch=touch)
        batched.reset()
    build = time.perf_counter() - t0
    dev = batched.tensors["qpos"].device
    sizes = {a: batched.n_controls(a) for a in batched.agents}
    gen = torch.Generator(device=dev).manual_seed(0)
    resets = [0]

    def one_step():
        acts = {a: torch.rand((nworld, n), generator=gen, device=dev) * 2.0 - 1.0
                for a, n in sizes.items()}
        if not with_task:
            return batched.step(acts)
        obs, _, term, trunc, infos = tenv.step(acts)
        resets[0] += int((term | trunc).sum())
        return obs, infos["instability"] > 0

    t1 = time.perf_counter()
    for _ in range(warmup):
        one_step()
    _sync(torch, dev)
    warm = time.perf_counter() - t1
    unstable = 0
    t2 = time.perf_counter()
    for _ in range(steps):
        _, bad = one_step()
        unstable += int(bad.sum())
    _sync(torch, dev)
    seconds = time.perf_counter() - t2
    reset_ms = None
    if with_task:
        t3 = time.perf_counter()
        tenv.reset()
        _sync(torch, dev)
        reset_ms = 1e3 * (time.perf_counter() - t3) / nworld
    n_agents = len(batched.agents)
    env.close()
    return {"worlds": nworld, "agents": n_agents, "steps": steps, "seconds": seconds,
            "agent_steps_per_s": nworld * n_agents * steps / seconds,
            "world_steps_per_s": nworld * steps / seconds,
            "physics_steps_per_s": nworld * steps * batched.frame_skip / seconds,
            "build_s": build, "warmup_s": warm, "warmup_steps": warmup,
            "unstable_resets": unstable, "task": bool(with_task), "resets": resets[0],
            "touch": batched.skin is not None, "reset_ms_per_world": reset_ms,
            "reset_bank": reset_bank if with_task else None,
            "eyes": None if batched.eyes is None else eyes}


def measure(worlds=WORLDS, steps: int = 100, warmup: int = 2, device: str | None = None,
            progress=None, with_task: bool = False, touch: bool = True,
            reset_bank: int | None = None, eyes: int | None = None) -> dict:
    """Every number of worlds in ``worlds`` (:func:`measure_one`), with the device and the
    machine; ``progress``: called with each result as it comes; ``with_task``: the task's
    logic and autoresets in each step too; ``touch``: the hand skins read each step;
    ``reset_bank``: the task's resets from that many starts kept (:class:`BatchedTaskEnv`);
    ``eyes``: both eyes of every agent rendered each step, that many pixels square."""
    dev = pick_device(device)
    results = []
    for n in worlds:
        results.append(measure_one(int(n), steps, warmup, dev, with_task=with_task,
                                   touch=touch, reset_bank=reset_bank, eyes=eyes))
        if progress is not None:
            progress(results[-1])
    task = ("high_five_v0, 2 infants" + (", hand skins" if touch else ", no touch")
            + (f", eyes {eyes}x{eyes}" if eyes else "")
            + (", with the task's logic and resets" if with_task else "")
            + (f" (a bank of {reset_bank} starts)" if with_task and reset_bank else ""))
    return {"device": dev, "device_name": describe(dev), "task": task,
            "machine": machine_info(), "results": results}


def _sync(torch, device) -> None:
    if device.type == "cuda":
        torch.cuda.synchronize(device)


def format_results(out: dict) -> str:
    """A table of the results with the device named (``no GPU: Warp's CPU device`` when so)."""
    lines = [f"MuJoCo Warp, {out['task']}; device: {out['device']} ({out['device_name']}); "
             f"CPU: {out['machine'].get('cpu', 'unknown')}",
             f"{'worlds':>7} {'steps':>6} {'agent-steps/s':>14} {'world-steps/s':>14} "
             f"{'physics steps/s':>16} {'build s':>8} {'warm-up s':>10} {'resets':>7}"]
    task = any(r.get("task") for r in out["results"])
    if task:   # the episodes that ended (and were reset) in the timed steps; a reset's cost
        lines[-1] += f" {'episodes ended':>15} {'reset ms/world':>15}"
    for r in out["results"]:
        lines.append(f"{r['worlds']:>7} {r['steps']:>6} {r['agent_steps_per_s']:>14.1f} "
                     f"{r['world_steps_per_s']:>14.1f} {r['physics_steps_per_s']:>16.1f} "
                     f"{r['build_s']:>8.1f} {r['warmup_s']:>10.1f} {r['unstable_resets']:>7}"
                     + (f" {r.get('resets', 0):>15} {r.get('reset_ms_per_world') or 0.0:>15.3f}"
                        if task else ""))
    if out["device"] == "cpu":
        lines.append("no GPU: Warp's CPU device; these figures say nothing of a GPU's")
    return "\n".join(lines)
