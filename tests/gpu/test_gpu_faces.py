"""Facial expressions on the device (:mod:`mimo_social.gpu.faces`), on Warp's CPU device: an
expression given to ``BatchedEnv.step`` is drawn on that world's face (the partner's eyes see
it as the CPU's eyes do) and read by proprioception's ``face`` component as on the CPU; resets
bring each world's start back; bad expressions are refused by name."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco_warp", reason="mujoco_warp cannot be imported: the gpu extra "
                                          "(pip install -e '.[gpu]') is not installed")

from mimo_social.envs import high_five_v0  # noqa: E402
from mimo_social.expressions.faces import EXPRESSIONS  # noqa: E402
from mimo_social.gpu import BatchedEnv, BatchedTaskEnv  # noqa: E402

ZOOM = {"width": 48, "height": 48, "field_of_view": 20}     # the partner's face fills the eye
SURPRISED = EXPRESSIONS.index("surprised")
PROPRIO = {"components": ("qpos", "face")}


def _make(**kw):
    return high_five_v0.parallel_env(vision=ZOOM, proprioception=PROPRIO, **kw)


def _cpu_steps(expression, steps=2):
    """The CPU env after ``steps`` zero-motor steps with infant_1 showing ``expression``."""
    env = _make()
    obs, _ = env.reset(seed=0)
    n = {a: env.action_space(a)["motors"].shape[0] for a in env.possible_agents}
    for _ in range(steps):
        obs, *_ = env.step({a: {"motors": np.zeros(n[a], np.float32),
                                "expression": expression if a == "infant_1" else 0}
                            for a in env.possible_agents})
    return obs


ALL = np.arange(len(EXPRESSIONS))


@pytest.fixture(scope="module")
def stepped():
    """Seven worlds, infant_1 showing expression ``w`` in world ``w``, two steps."""
    b = BatchedEnv(_make(), len(ALL), device="cpu", seed=0)
    b.reset()
    zero = {a: np.zeros((len(ALL), b.n_controls(a)), np.float32) for a in b.agents}
    for _ in range(2):
        obs, _ = b.step(zero, expressions={"infant_1": ALL})
    return b, obs


@pytest.fixture(scope="module")
def cpu():
    return {int(e): _cpu_steps(int(e)) for e in ALL}


def test_the_partner_sees_the_expression_shown_in_its_world(stepped, cpu):
    """infant_0's eye on infant_1's face: the change each expression makes to the image
    (against world 0's neutral face) is the change it makes on the CPU (correlation above 0.6:
    measured 0.66-0.84; with the face textures unscaled, -0.15 to 0.25 for four of them)."""
    _, obs = stepped
    dev = obs["infant_0"]["eye_left"].numpy().astype(float)
    base = cpu[0]["infant_0"]["eye_left"].astype(float)
    for e in ALL[1:]:
        dev_change = dev[e] - dev[0]
        cpu_change = cpu[int(e)]["infant_0"]["eye_left"].astype(float) - base
        assert np.abs(dev_change).mean() > 1.0 and np.abs(cpu_change).mean() > 1.0
        corr = np.corrcoef(dev_change.ravel(), cpu_change.ravel())[0, 1]
        print(EXPRESSIONS[e], "change, device against CPU: correlation", round(corr, 3))
        assert corr > 0.6, (EXPRESSIONS[e], corr)


def test_proprioception_reads_the_own_expression_as_the_cpu(stepped, cpu):
    _, obs = stepped
    face = slice(-len(EXPRESSIONS), None)
    for e in ALL:
        for a in ("infant_0", "infant_1"):
            np.testing.assert_array_equal(obs[a]["proprioception"][e, face].numpy(),
                                          cpu[int(e)][a]["proprioception"][face])


def test_a_reset_brings_the_start_expression_back(stepped):
    b, _ = stepped
    b.faces.set({"infant_1": ALL})
    obs = b.reset(ALL == 3)
    face = slice(-len(EXPRESSIONS), None)
    assert obs["infant_1"]["proprioception"][3, face].argmax() == 0
    assert b.faces.expression[:, 1].tolist() == [0, 1, 2, 0, 4, 5, 6]
    env = _make()
    env.reset(seed=3)
    b.load([5], [b.snapshot(env.unwrapped)])        # a CPU reset: neutral
    assert b.faces.expression[:, 1].tolist() == [0, 1, 2, 0, 4, 0, 6]


@pytest.mark.parametrize("given, match", [
    ({"infant_1": np.where(ALL == 2, 7, ALL)}, "infant_1: expression 7 not allowed; allowed: "
                                               "0 to 6"),
    ({"infant_1": ALL.astype(float)}, "infant_1: expression of shape"),
    ({"infant_1": np.array([0, 1, 2])}, "infant_1: expression of shape"),
    ({"infant_9": ALL}, "unknown agent 'infant_9'")])
def test_a_bad_expression_is_refused_by_name(stepped, given, match):
    b, _ = stepped
    zero = {a: np.zeros((len(ALL), b.n_controls(a)), np.float32) for a in b.agents}
    with pytest.raises(ValueError, match=match):
        b.step(zero, expressions=given)


def test_an_agent_without_expressions_is_refused():
    b = BatchedEnv(high_five_v0.parallel_env(expressions=False), 1, device="cpu")
    b.reset()
    zero = {a: np.zeros((1, b.n_controls(a)), np.float32) for a in b.agents}
    with pytest.raises(ValueError, match="infant_0: expression given, but this agent's actions "
                                         "have no expression"):
        b.step(zero, expressions={"infant_0": np.array([1])})


def test_the_task_env_passes_the_learners_expressions_on():
    tenv = BatchedTaskEnv(high_five_v0.scripted_env(vision=ZOOM), 1, device="cpu")
    tenv.reset()
    zero = {"infant_0": np.zeros((1, tenv.n_controls("infant_0")), np.float32)}
    tenv.step(zero, expressions={"infant_0": np.array([SURPRISED])})
    assert tenv.batched.faces.expression[0, 0] == SURPRISED
    with pytest.raises(ValueError, match="expressions given for \\['infant_1'\\]"):
        tenv.step(zero, expressions={"infant_1": np.array([1])})


def test_a_bad_expression_changes_no_agents_face(stepped):
    b, _ = stepped
    before = b.faces.expression.clone()
    zero = {a: np.zeros((len(ALL), b.n_controls(a)), np.float32) for a in b.agents}
    with pytest.raises(ValueError, match="infant_1: expression 7 not allowed"):
        b.step(zero, expressions={"infant_0": ALL[::-1].copy(), "infant_1": ALL + 3})
    assert (b.faces.expression == before).all()


def test_the_gym_vector_env_takes_the_expression_in_its_actions():
    """``GymVectorEnv(..., expressions=True)``: a Dict action of the motors and the expression;
    each world's learner face shows its own; the motors' Box alone without it; refused for a
    learner without expressions and for an action without the expression."""
    from mimo_social.gpu import GymVectorEnv
    v = GymVectorEnv(high_five_v0.scripted_env(max_steps=5), 2, device="cpu", expressions=True)
    assert set(v.single_action_space.spaces) == {"motors", "expression"}
    v.reset(seed=0)
    act = v.action_space.sample()
    act["expression"] = np.array([SURPRISED, 1])
    v.step(act)
    assert v.tenv.batched.faces.expression[:, 0].tolist() == [SURPRISED, 1]
    with pytest.raises(ValueError, match="infant_0: actions must be a dict with 'motors'"):
        v.step(act["motors"])
    plain = GymVectorEnv(high_five_v0.scripted_env(max_steps=5), 1, device="cpu")
    assert plain.single_action_space.shape == (plain.tenv.n_controls("infant_0"),)
    with pytest.raises(ValueError, match="infant_0: expressions=True, but this agent's actions "
                                         "have no expression"):
        GymVectorEnv(high_five_v0.scripted_env(expressions=False), 1, device="cpu",
                     expressions=True)


def test_the_torchrl_env_takes_the_learners_expressions():
    """``TorchRLEnv(..., expressions=True)``: ``(group, "expression")`` a Categorical(7) beside
    the motors; a rollout passes TorchRL's spec check and the faces show what was chosen."""
    from tensordict import TensorDict
    from torchrl.envs.utils import check_env_specs

    from mimo_social.gpu import TorchRLEnv
    env = TorchRLEnv(high_five_v0.parallel_env(max_steps=4), 2, device="cpu", expressions=True)
    spec = env.action_spec["agents", "expression"]
    assert spec.shape == (2, 2) and spec.space.n == len(EXPRESSIONS)
    check_env_specs(env)
    td = env.reset()
    act = env.action_spec.rand()
    act["agents", "expression"] = env.tenv.torch.tensor([[SURPRISED, 1], [2, 0]])
    td.update(act)
    env.step(td)
    assert env.tenv.batched.faces.expression.tolist() == [[SURPRISED, 1], [2, 0]]
    assert isinstance(td, TensorDict)
    with pytest.raises(ValueError, match="expressions=True, but this agent's actions"):
        TorchRLEnv(high_five_v0.parallel_env(expressions=False), 1, device="cpu",
                   expressions=True)
