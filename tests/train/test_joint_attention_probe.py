"""The joint-attention probe (scripts/joint_attention_probe.py): its image shift (``--augment``:
both eyes of a step move by the same offset, edges replicated, nothing else changes) and its
face-watching recording (``--look face``, with every toy's direction for ``--label direction``)."""

from __future__ import annotations

from itertools import combinations

import mujoco
import numpy as np
import torch

from mimo_social.train.envs import make_env


def test_both_eyes_of_a_step_shift_together_and_the_vector_does_not(load_script):
    probe = load_script("joint_attention_probe")
    n, pad = 6, 3
    left = torch.arange(n * 3 * 16 * 16, dtype=torch.float32).reshape(n, 3, 16, 16)
    batch = {"left_eye": left, "right_eye": left + 1.0, "vector": torch.ones(n, 5)}
    out = probe.shift_images(batch, ("left_eye", "right_eye"), pad, np.random.default_rng(0))
    assert out["left_eye"].shape == left.shape and torch.equal(out["vector"], batch["vector"])
    assert torch.equal(out["right_eye"], out["left_eye"] + 1.0)      # the same offset
    shifted = 0
    for i in range(n):          # each image is its original moved by one (dy, dx) in the pad
        padded = torch.nn.functional.pad(left[i:i + 1], (pad,) * 4, mode="replicate")[0]
        hits = [(dy, dx) for dy in range(2 * pad + 1) for dx in range(2 * pad + 1)
                if torch.equal(padded[:, dy:dy + 16, dx:dx + 16], out["left_eye"][i])]
        assert len(hits) == 1
        shifted += hits[0] != (pad, pad)
    assert shifted >= n - 1


def test_watching_the_face_keeps_steps_with_every_toys_direction(load_script):
    """``--look face``: the learner watches its partner's face; every kept step has the toy the
    partner looks at and each toy's direction from the learner's head, the toys apart by more
    than the direction label's errors that still name the right one."""
    probe = load_script("joint_attention_probe")
    env = make_env("joint_attention", per_agent=[{"vision": {"width": 16, "height": 16}}, {}])
    try:
        obs, labels, episode, directions = probe.record(env, 1, 25, 0.0, 1000, look="face")
        core = env.unwrapped.parallel.unwrapped          # at the episode's last step
        data, cams = core.world.data, list(core.world.agents[0].eye_cameras)
        origin = data.cam_xpos[cams].mean(axis=0)
        gaze = -data.cam_xmat[cams].reshape(2, 3, 3)[:, :, 2].sum(axis=0)
        face = data.site_xpos[mujoco.mj_name2id(core.world.model, mujoco.mjtObj.mjOBJ_SITE,
                                                "infant_1/head_centre")] - origin
        off = np.degrees(np.arccos(gaze @ face / np.linalg.norm(gaze) / np.linalg.norm(face)))
    finally:
        env.close()
    assert off < 10.0                     # the learner's gaze on its partner's face
    n = len(labels)
    assert n > 5 and set(np.unique(episode)) == {0}
    assert obs["eye_left"].shape[0] == n and directions.shape == (n, 4, 2)
    assert set(labels.tolist()) <= {0, 1, 2, 3} and len(set(labels.tolist())) >= 2
    apart = [np.linalg.norm(directions[:, a] - directions[:, b], axis=1)
             for a, b in combinations(range(4), 2)]
    assert np.min(apart) > 20.0          # degrees between any two toys, as seen by the learner
    assert np.all(directions[:, :, 1] < 0.0)          # on the floor: below the learner's head
