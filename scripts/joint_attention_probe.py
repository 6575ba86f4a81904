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

``--look face``: the learner does not follow; it looks at its partner's face all the time
(:class:`~mimo_social.partners.gaze.GazeAtTarget` on the partner's ``head_centre`` site, head
and eyes, DART noise as above), and every ``--every``-th step at which the partner looks at a
toy is kept: can the toy be read while the learner watches the face, as an infant checks the
face before it follows? With a fovea the partner's eyes are then magnified at the centre.
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np
import torch
from gymnasium import spaces

from mimo_social.cli._args import env_kwargs
from mimo_social.partners.gaze import GazeAtTarget
from mimo_social.train.demonstrations import Demonstrator, demonstrator
from mimo_social.train.envs import make_env
from mimo_social.train.encoders import EyesExtractor, image_space_keys


#: the direction label's scale in the loss (degrees)
SCALE_DEG = 30.0


def watcher():
    """The learner's gaze held on its partner's face (``--look face``)."""
    return GazeAtTarget(targets=["infant_1/head_centre"], hold_s=(3600.0, 3600.0),
                        head_share=1.0)


def toy_directions(core) -> np.ndarray:
    """Each toy's direction (azimuth, elevation; degrees, world frame) from the learner's head
    centre: where a follower must turn to see it."""
    data, model = core.world.data, core.world.model
    head = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "infant_0/head_centre")
    d = data.xpos[core.task.toy_bodies] - data.site_xpos[head]
    return np.degrees(np.stack([np.arctan2(d[:, 1], d[:, 0]),
                                np.arctan2(d[:, 2], np.hypot(d[:, 0], d[:, 1]))], axis=1))


def record(env, episodes: int, every: int, noise: float, first: int, look: str = "follow"):
    """Observations at every ``every``-th step with a target the learner does not look at,
    their toy, episode and every toy's direction (``look``: ``follow``, the scripted follower,
    or ``face``)."""
    teacher = Demonstrator(watcher if look == "face" else demonstrator("joint_attention"),
                           env, noise)
    obs_list, labels, episode, directions = [], [], [], []
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
                directions.append(toy_directions(teacher.core))
        teacher.obs.clear()
        teacher.actions.clear()
    if not obs_list:
        raise SystemExit(f"joint_attention_probe: no labelled step in {episodes} episodes at "
                         f"--every {every}; allowed: more episodes or a smaller --every")
    stacked = {key: np.stack([o[key] for o in obs_list]) for key in obs_list[0]}
    return stacked, np.array(labels), np.array(episode), np.array(directions, np.float32)


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
    p.add_argument("--label", choices=("toy", "direction"), default="toy",
                   help="what the head names: the toy (classes), or the direction of the toy "
                        "(regressed; right when the nearest toy to it is the target)")
    p.add_argument("--look", choices=("follow", "face"), default="follow",
                   help="the learner's gaze: the scripted follower's, or held on the partner's "
                        "face")
    a = p.parse_args(argv)
    torch.set_num_threads(a.threads)
    torch.manual_seed(0)
    env = make_env("joint_attention", **a.env_kwargs)
    t0 = time.time()
    if a.load:
        with np.load(a.load) as data:
            y, ep = data["labels"], data["episode"]
            dirs = data["directions"] if "directions" in data.files else None
            obs = {k[4:]: data[k] for k in data.files if k.startswith("obs_")}
    else:
        obs, y, ep, dirs = record(env, a.episodes, a.every, a.noise, a.seed, a.look)
    if a.save:
        np.savez(a.save, labels=y, episode=ep, directions=dirs,
                 **{f"obs_{k}": v for k, v in obs.items()})
    if a.label == "direction" and dirs is None:
        raise SystemExit(f"joint_attention_probe: --label direction needs the toys' directions; "
                         f"{a.load} has none (recorded before they were kept): record again")
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
    regress = a.label == "direction"
    head = torch.nn.Linear(encoder.features_dim, 2 if regress else 4)
    params = list(encoder.parameters()) + list(head.parameters())
    optimiser = torch.optim.Adam(params, lr=a.lr)
    tensors = {k: torch.as_tensor(v) for k, v in obs.items()}
    target = torch.as_tensor(y)
    if regress:     # the target toy's direction, scaled; each step's toys to name the nearest
        toys = torch.as_tensor(dirs) / SCALE_DEG
        aim = toys[torch.arange(len(y)), target]
    rng = np.random.default_rng(0)

    def loss_of(out, b):
        if regress:
            return torch.nn.functional.mse_loss(out, aim[b])
        return torch.nn.functional.cross_entropy(out, target[b])

    def accuracy(mask) -> str:
        idx = np.flatnonzero(mask)
        right, error = 0, 0.0
        with torch.no_grad():
            for s in range(0, len(idx), 256):
                b = idx[s:s + 256]
                out = head(encoder({k: v[b].float() for k, v in tensors.items()}))
                if regress:     # the nearest toy to the read direction
                    named = ((toys[b] - out[:, None, :]) ** 2).sum(-1).argmin(1)
                    error += float((out - aim[b]).norm(dim=1).sum()) * SCALE_DEG
                else:
                    named = out.argmax(1)
                right += int((named == target[b]).sum())
        return f"{right / len(idx):.2f}" + (f" ({error / len(idx):.1f} deg off)" if regress
                                              else "")

    for epoch in range(a.epochs):
        order = rng.permutation(np.flatnonzero(train))
        for s in range(0, len(order), 64):
            b = order[s:s + 64]
            batch = {k: v[b].float() for k, v in tensors.items()}
            if a.augment:
                batch = shift_images(batch, encoder.image_keys, a.augment, rng)
            loss = loss_of(head(encoder(batch)), b)
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
        print(f"epoch {epoch + 1}: train accuracy {accuracy(train)}, test (new placements) "
              f"{accuracy(test)}, {time.time() - t0:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
