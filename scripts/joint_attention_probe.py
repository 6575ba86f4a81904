"""Can a CNN read from the learner's eyes which toy its partner looks at? A supervised probe.

Joint attention's clones fit their demonstrations and fail new toy placements (issue 30): is the
partner's gaze readable at all from the learner's 96x96 eye images by the recipe's CNN, given
this many episodes? This probe records ``--episodes`` episodes of the scripted follower
(``GazeFollowController``, with DART noise ``--noise`` so the learner's own gaze varies), keeps
every ``--every``-th step at which the partner looks at a toy and the learner does not (yet)
look at that toy, labelled with that toy (the task's ``target`` info: 4 toys, each its own
colour; off the target, the toy in the middle of the learner's view does not give the answer
away: the image must be read for the partner's gaze), and trains the recipe's image encoder
(:class:`~mimo_social.train.encoders.EyesExtractor`: both eyes and the normalised vector)
with a linear head to name the toy (cross-entropy, Adam). Episodes are split: the last
``--test`` episodes are never trained on, so their accuracy measures reading new placements.
Chance: the share of the most frequent toy. Prints per epoch the train and test accuracy.

    OMP_NUM_THREADS=1 python3 scripts/joint_attention_probe.py --episodes 200 --test 40 \
        --every 10 --epochs 10

``--save FILE`` keeps the recorded steps (``.npz``) and ``--load FILE`` trains on them without
recording again (the same split: ``--episodes`` and ``--test`` must match the recording).
``--augment PX`` shifts every training image by up to PX pixels (pad by replication, crop; the
same shift for both eyes of a step; held-out images are never shifted); ``--images-only`` drops
the vector (proprioception and the other senses) from the encoder's input, so the toy must be
read from the images alone (the learner's own posture cannot name an episode's layout).

``--env-kwargs`` sets the env's options (JSON), e.g. foveated 64x64 eyes that magnify the
partner's face at the centre of the view: ``--env-kwargs '{"per_agent": [{"vision": {"width":
64, "height": 64, "fovea": 4}}, {}]}'``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch
from gymnasium import spaces

from mimo_social.cli._args import env_kwargs
from mimo_social.train.demonstrations import Demonstrator, demonstrator
from mimo_social.train.envs import make_env
from mimo_social.train.encoders import EyesExtractor, image_space_keys


def record(env, episodes: int, every: int, noise: float, first: int):
    """Observations at every ``every``-th step with a target the learner does not look at,
    their toy and episode."""
    teacher = Demonstrator(demonstrator("joint_attention"), env, noise)
    obs_list, labels, episode = [], [], []
    for k in range(episodes):
        obs, info = env.reset(seed=first + k)
        teacher.reset(env, "infant_0", np.random.default_rng(first + k))
        step, done = 0, False
        while not done:
            action = teacher.act(env, "infant_0", obs)
            obs, _, term, trunc, info = env.step(action)
            done = term or trunc
            step += 1
            if info["target"] >= 0 and info["looked_at"] != info["target"] \
                    and step % every == 0:
                obs_list.append({key: np.array(v) for key, v in obs.items()})
                labels.append(int(info["target"]))
                episode.append(k)
        teacher.obs.clear()
        teacher.actions.clear()
    if not obs_list:
        raise SystemExit(f"joint_attention_probe: no labelled step in {episodes} episodes at "
                         f"--every {every}; allowed: more episodes or a smaller --every")
    stacked = {key: np.stack([o[key] for o in obs_list]) for key in obs_list[0]}
    return stacked, np.array(labels), np.array(episode)


def shift_images(batch: dict[str, torch.Tensor], keys, pad: int,
                 rng: np.random.Generator) -> dict[str, torch.Tensor]:
    """Each step's images shifted by one random offset of up to ``pad`` pixels (both eyes the
    same), edges replicated: a held-out layout's partner is a few pixels from where a training
    one was."""
    out = dict(batch)
    n = next(iter(batch.values())).shape[0]
    dy, dx = rng.integers(0, 2 * pad + 1, size=(2, n))
    for key in keys:
        x = batch[key]
        h, w = x.shape[-2], x.shape[-1]
        padded = torch.nn.functional.pad(x, (pad, pad, pad, pad), mode="replicate")
        rows = torch.as_tensor(dy)[:, None] + torch.arange(h)[None, :]
        cols = torch.as_tensor(dx)[:, None] + torch.arange(w)[None, :]
        idx = torch.arange(n)[:, None, None, None]
        ch = torch.arange(x.shape[1])[None, :, None, None]
        out[key] = padded[idx, ch, rows[:, None, :, None], cols[:, None, None, :]]
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--episodes", type=int, default=200)
    p.add_argument("--test", type=int, default=40, help="the last episodes, held out")
    p.add_argument("--every", type=int, default=10)
    p.add_argument("--noise", type=float, default=0.1)
    p.add_argument("--epochs", type=int, default=10)
    p.add_argument("--lr", type=float, default=3e-4)
    p.add_argument("--seed", type=int, default=20_000)
    p.add_argument("--env-kwargs", type=env_kwargs, default={},
                   help='the env\'s options as JSON, e.g. \'{"per_agent": [{"vision": '
                        '{"width": 64, "height": 64, "fovea": 4}}, {}]}\' (foveated eyes)')
    p.add_argument("--save", default=None, help="keep the recorded steps in this .npz")
    p.add_argument("--load", default=None, help="train on the steps of this .npz")
    p.add_argument("--augment", type=int, default=0,
                   help="shift training images by up to this many pixels (0: none)")
    p.add_argument("--images-only", action="store_true",
                   help="the encoder reads the images only, not the vector")
    p.add_argument("--threads", type=int, default=1)
    a = p.parse_args(argv)
    torch.set_num_threads(a.threads)
    torch.manual_seed(0)
    env = make_env("joint_attention", **a.env_kwargs)
    t0 = time.time()
    if a.load:
        with np.load(a.load) as data:
            y, ep = data["labels"], data["episode"]
            obs = {k[4:]: data[k] for k in data.files if k.startswith("obs_")}
    else:
        obs, y, ep = record(env, a.episodes, a.every, a.noise, a.seed)
    if a.save:
        np.savez(a.save, labels=y, episode=ep, **{f"obs_{k}": v for k, v in obs.items()})
    train, test = ep < a.episodes - a.test, ep >= a.episodes - a.test
    print(f"{len(y)} labelled steps ({train.sum()} train, {test.sum()} test) from {a.episodes} "
          f"episodes in {time.time() - t0:.0f} s; toys {np.bincount(y, minlength=4).tolist()}; "
          f"chance (most frequent toy, test) {np.bincount(y[test]).max() / test.sum():.2f}",
          flush=True)
    space = env.observation_space
    if a.images_only:
        keep = image_space_keys(space)
        space = spaces.Dict({k: space[k] for k in keep})
        obs = {k: obs[k] for k in keep}
    encoder = EyesExtractor(space, normalize_vector=True, norm_min_std=0.01)
    head = torch.nn.Linear(encoder.features_dim, 4)
    params = list(encoder.parameters()) + list(head.parameters())
    optimiser = torch.optim.Adam(params, lr=a.lr)
    tensors = {k: torch.as_tensor(v) for k, v in obs.items()}
    target = torch.as_tensor(y)
    rng = np.random.default_rng(0)

    def accuracy(mask) -> float:
        idx = np.flatnonzero(mask)
        right = 0
        with torch.no_grad():
            for s in range(0, len(idx), 256):
                b = idx[s:s + 256]
                logits = head(encoder({k: v[b].float() for k, v in tensors.items()}))
                right += int((logits.argmax(1) == target[b]).sum())
        return right / len(idx)

    for epoch in range(a.epochs):
        order = rng.permutation(np.flatnonzero(train))
        for s in range(0, len(order), 64):
            b = order[s:s + 64]
            batch = {k: v[b].float() for k, v in tensors.items()}
            if a.augment:
                batch = shift_images(batch, encoder.image_keys, a.augment, rng)
            logits = head(encoder(batch))
            loss = torch.nn.functional.cross_entropy(logits, target[b])
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
        print(f"epoch {epoch + 1}: train accuracy {accuracy(train):.2f}, test (new placements) "
              f"{accuracy(test):.2f}, {time.time() - t0:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
