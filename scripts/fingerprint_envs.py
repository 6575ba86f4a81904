"""Fingerprint every catalogue env: a refactor that changes no behaviour keeps every hash.

For each catalogue entry: 15 steps of seeded random actions on ``parallel_env()`` (reset with seed
3, the action spaces seeded 7), and 25 steps of the task's scripted controller on
``scripted_env()`` (reset with seed 5, the controller reset with a generator seeded 5); a
SHA-256 over every observation, reward, termination, truncation and info, printed as 16 hex
digits per form. Run it before and after a change and compare (``--json FILE`` writes them):

    python3 scripts/fingerprint_envs.py --json before.json     # on the old commit
    python3 scripts/fingerprint_envs.py --json after.json      # on the new one
    cmp before.json after.json

A change of the physics (MuJoCo's version, the solver settings) changes the hashes by design.
"""

from __future__ import annotations

import argparse
import hashlib
import json

import numpy as np

from mimo_social.envs.catalog import CATALOG


def _feed(h, x) -> None:
    if isinstance(x, dict):
        for k in sorted(x, key=str):
            h.update(str(k).encode())
            _feed(h, x[k])
    elif isinstance(x, (list, tuple)):
        for v in x:
            _feed(h, v)
    elif isinstance(x, np.ndarray):
        h.update(np.ascontiguousarray(x).tobytes())
    elif isinstance(x, (float, np.floating)):
        h.update(np.float64(x).tobytes())
    else:
        h.update(repr(x).encode())


def random_steps(entry, steps: int = 15) -> str:
    env = entry.parallel_env()
    h = hashlib.sha256()
    _feed(h, env.reset(seed=3))
    spaces = {a: env.action_space(a) for a in env.agents}
    for s in spaces.values():
        s.seed(7)
    for t in range(steps):
        if not env.agents:
            _feed(h, env.reset(seed=4 + t))
        _feed(h, env.step({a: spaces[a].sample() for a in env.agents}))
    env.close()
    return h.hexdigest()[:16]


def controller_steps(entry, steps: int = 25) -> str:
    if entry.controller is None:
        return "-"
    env = entry.scripted_env()
    h = hashlib.sha256()
    obs, infos = env.reset(seed=5)
    _feed(h, obs)
    agent = env.agents[0]
    controller = entry.controller()
    controller.reset(env.unwrapped, agent, np.random.default_rng(5))
    for _ in range(steps):
        if not env.agents:
            break
        out = env.step({agent: controller.act(env.unwrapped, agent, obs[agent])})
        obs = out[0]
        _feed(h, out)
    env.close()
    return h.hexdigest()[:16]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", help="write {task: [random, controller]} here")
    args = parser.parse_args()
    out = {}
    for entry in CATALOG:
        out[entry.name] = [random_steps(entry), controller_steps(entry)]
        print(entry.name, *out[entry.name], flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=1)


if __name__ == "__main__":
    main()
