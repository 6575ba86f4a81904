"""The full-body touch skin (issue 3), through the public env API.

Scenes: infants held rigid in a pose ("statues": every joint frozen, free base, so MuJoCo's
parent-child contact filter works) with props laid on them, free-play infants, and two statues
whose right hands are pressed together. Forces from the skin are compared with MuJoCo's own
contact forces (``mujoco.mj_contactForce``).
"""

import os

import mujoco
import numpy as np
import pytest

import mimo_social  # noqa: F401
from mimo_social.body.postures import POSTURES
from mimo_social.body.tables import load_body
from mimo_social.envs import free_play_v0
from mimo_social.core.config import ConfigError
from mimo_social.core.env import MimoParallelEnv
from mimo_social.body.joint_groups import held_posture
from mimo_social.core.task import Task
from mimo_social.core.world import AgentSetup, Prop
from mimo_social.figures import hand_ball_scene
from mimo_social.senses import skin as skin_module
from mimo_social.senses.touch import save_skin_png
from mimo_social.senses.contact_forces import contact_forces

pytestmark = pytest.mark.text_infos   # these tests read the text infos (info_text=True)

G = 9.81
# right arm forward, palm up (deg), sitting
PALM_UP = {"right_shoulder_horizontal": -26.0, "right_shoulder_abduction": -29.0,
           "right_shoulder_rotation": 23.0, "right_elbow": -98.0, "right_wrist_rotation": -56.0,
           "right_wrist_flexion": 0.0, "right_wrist_ulnar": 0.0, "right_fingers": 0.0}
# standing 0.3 m apart, face to face: this right arm pose (deg) puts the right palm in the
# plane between them, so the two right hands overlap by 1 mm (fingers on palm and fingers)
HIGH_FIVE = {"right_shoulder_horizontal": 91.71, "right_shoulder_abduction": 24.69,
             "right_shoulder_rotation": -28.65, "right_elbow": -88.35,
             "right_wrist_rotation": 17.7, "right_wrist_flexion": 52.63,
             "right_wrist_ulnar": -52.97, "right_fingers": 0.0}


@pytest.fixture(autouse=True, scope="module")
def _skin_cache(tmp_path_factory):
    """Keep the disk cache of this module's skins out of the user's cache directory."""
    old = os.environ.get("MIMO_SOCIAL_CACHE")
    os.environ["MIMO_SOCIAL_CACHE"] = str(tmp_path_factory.mktemp("mimo_cache"))
    yield
    if old is None:
        os.environ.pop("MIMO_SOCIAL_CACHE", None)
    else:
        os.environ["MIMO_SOCIAL_CACHE"] = old


class Statues(Task):
    """Infants held rigid (every joint frozen at the posture plus ``arm`` angles), free base."""

    name = "statues"

    def __init__(self, n_agents, places, arm=None, props=()):
        super().__init__(n_agents)
        self.places, self.arm, self._props = places, arm or {}, list(props)

    def setup(self, i, config):
        angles = dict(POSTURES[config.posture]["joints"])
        angles.update(self.arm)
        frozen = held_posture(load_body(config.hands), keep=(), angles=angles)
        pos, facing = self.places[i]
        return AgentSetup(config, position=pos, facing=facing, frozen=frozen, actuated=())

    def props(self):
        return self._props


def statues(places, posture, arm=None, props=(), **touch):
    """An env of statues; ``touch`` settings as keyword arguments; text infos (the touched parts
    by name), also where a module-scoped fixture makes it before the text_infos mark applies."""
    env = MimoParallelEnv(Statues(len(places), places, arm, props), touch=touch or True,
                          posture=posture, expressions=False, proprioception=False,
                          info_text=True)
    env.reset(seed=0)
    return env


def rest(env, steps):
    action = {a: np.zeros(env.action_space(a).shape, np.float32) for a in env.agents}
    out = None
    for _ in range(steps):
        out = env.step(action)
    return out


def skin(env):
    return env.system("touch")


def part_geoms(env, agent, part):
    m = env.world.model
    return set(np.flatnonzero(m.geom_bodyid == m.body(f"infant_{agent}/{part}").id).tolist())


def mujoco_normal(env, geoms, others=None):
    """Summed normal force (mj_contactForce) of the contacts of ``geoms`` (with ``others``)."""
    m, d = env.world.model, env.world.data
    f = np.zeros(6)
    total = 0.0
    for i in range(d.ncon):
        g = set(d.contact.geom[i].tolist())
        if g & geoms and (others is None or g & others):
            mujoco.mj_contactForce(m, d, i, f)
            total += f[0]
    return total


def contact_points(env, geoms):
    d = env.world.data
    return np.array([d.contact.pos[i] for i in range(d.ncon)
                     if set(d.contact.geom[i].tolist()) & geoms]).reshape(-1, 3)


def lay_on(env, prop, point, normal, half_height):
    """Put a free prop with its centre ``half_height`` + 0.5 mm from ``point`` along ``normal``."""
    w = env.world
    q = w.prop_qpos[prop]
    w.data.qpos[q:q + 3] = point + (half_height + 0.0005) * normal
    w.data.qpos[q + 3:q + 7] = (1.0, 0.0, 0.0, 0.0)
    w.data.qvel[w.prop_dof[prop]:w.prop_dof[prop] + 6] = 0.0
    mujoco.mj_forward(w.model, w.data)


@pytest.fixture(scope="module", params=[1.0, 0.25], ids=["density1", "density0.25"])
def palm_box(request):
    """A sitting statue, right palm up, a 0.2 kg box resting on the palm. At density 0.25 the
    hand's points are 14 mm apart, so the response reaches 28 mm: farther than the 20 mm thick
    palm, so only the surface neighbourhoods keep the force off the back of the hand."""
    env = statues([((0.0, 0.0), (1.0, 0.0))], "sitting", PALM_UP,
                  [Prop("box", "box", (0.02, 0.02, 0.015), (1.0, 1.0, 0.015), 0.2)],
                  density=request.param)
    rest(env, 50)                                     # the sitting statue settles on the floor
    w = env.world
    a = w.agents[0]
    hand = w.model.site_bodyid[a.palm_sites[0]]
    R = w.data.xmat[hand].reshape(3, 3)
    palm_normal = -R[:, 1]                            # the mitten closes towards the hand's -y
    assert palm_normal[2] > 0.95                      # the palm faces up
    lay_on(env, "box", w.data.site_xpos[a.palm_sites[0]] + 0.01 * palm_normal, palm_normal, 0.015)
    q = w.prop_qpos["box"]
    quat = np.empty(4)
    mujoco.mju_mat2Quat(quat, R.ravel())              # the box square on the palm
    w.data.qpos[q + 3:q + 7] = quat
    mujoco.mj_forward(w.model, w.data)
    obs, _, _, _, infos = rest(env, 100)
    return env, obs, infos, palm_normal


def test_box_on_palm_conserves_force(palm_box):
    env, obs, infos, _ = palm_box
    view = skin(env).view("infant_0")
    box = {env.world.model.geom("box").id}
    felt = 0.0
    for part in ("right_hand", "right_fingers"):
        geoms = part_geoms(env, 0, part)
        mj = mujoco_normal(env, geoms)
        sensed = view[part]["normal_force"].sum()
        assert sensed == pytest.approx(mj, rel=0.01, abs=1e-9), part
        felt += mujoco_normal(env, geoms, box)
    assert view["right_hand"]["normal_force"].sum() > 1.0
    assert felt == pytest.approx(0.2 * G, rel=0.03)   # the box rests on the hand
    # the skin's total force vector on the hand balances the box's weight
    F = view["right_hand"]["forces"].sum(0) + view["right_fingers"]["forces"].sum(0)
    assert F == pytest.approx([0.0, 0.0, -0.2 * G], abs=0.06)
    assert infos["infant_0"]["touch"]["right_hand"] == {"self": False, "agents": [],
                                                       "object": True}


def test_box_on_palm_is_local(palm_box):
    env, obs, infos, palm_normal = palm_box
    system = skin(env)
    hand = system.view("infant_0")["right_hand"]
    s = hand["spacing"]
    pressed = hand["normal_force"] > 0
    assert pressed.sum() >= 5
    # no force bleeds through to the back of the hand: a back point gets force only if the way
    # round the palm's rim from a pressed point (>= the 20 mm thickness + its distance to the
    # rim) is shorter than the response's reach (2 spacings); at density 1 none is
    back = hand["normals"] @ palm_normal < -0.5
    x, z = hand["local_points"][:, 0], hand["local_points"][:, 2]
    rim = np.minimum(0.0281 - np.abs(x), np.minimum(z, 0.0416 - z))   # palm box, hand frame
    shielded = back & (0.02 + rim >= 2.0 * s)
    assert shielded.sum() >= 2
    assert np.all(hand["forces"][shielded] == 0.0)
    assert np.all(hand["normal_force"][shielded] == 0.0)
    # only points within the response's reach (2 spacings) of a contact feel anything ...
    contacts = contact_points(env, part_geoms(env, 0, "right_hand"))
    dist = np.linalg.norm(hand["points"][:, None] - contacts[None], axis=2).min(1)
    assert np.all(dist[pressed] < 2.0 * s + 1e-3)
    assert np.all(~pressed[dist > 2.5 * s])
    # ... and the point nearest to each contact does
    nearest = np.linalg.norm(hand["points"][:, None] - contacts[None], axis=2).argmin(0)
    assert np.all(pressed[nearest])
    # the observation is the body-frame view of the same forces, part after part
    a, b = system.layout("infant_0")["right_hand"]
    np.testing.assert_allclose(obs["infant_0"]["touch"][3 * a:3 * b],
                               hand["local_forces"].ravel(), rtol=1e-6, atol=1e-7)
    assert env.observation_space("infant_0").contains(obs["infant_0"])


def test_ball_resting_on_the_head():
    env = statues([((0.0, 0.0), (1.0, 0.0))], "lying",
                  props=[Prop("ball", "sphere", (0.04,), (1.0, 1.0, 0.04), 0.1)])
    rest(env, 50)
    w = env.world
    head = w.agents[0].head_geom
    centre, r = w.data.geom_xpos[head].copy(), w.model.geom_size[head, 0]
    lay_on(env, "ball", centre + [0.0, 0.0, r], np.array([0.0, 0.0, 1.0]), 0.04)
    _, _, _, _, infos = rest(env, 60)
    view = skin(env).view(0)["head"]
    ball = {w.model.geom("ball").id}
    on_head = mujoco_normal(env, {head}, ball)
    assert on_head == pytest.approx(0.1 * G, rel=0.02)           # the ball rests on the face
    # all contacts of the head (ball above, floor below) are conserved ...
    assert view["normal_force"].sum() == pytest.approx(mujoco_normal(env, {head}), rel=0.01)
    # ... and the ball's share lands on the face, the floor's on the back of the head
    up = view["normals"][:, 2] > 0.0
    assert view["normal_force"][up].sum() == pytest.approx(on_head, rel=0.01)
    top = contact_points(env, ball)
    far = np.linalg.norm(view["points"] - top[0], axis=1) > 2.5 * view["spacing"]
    assert np.all(view["normal_force"][up & far] == 0.0)
    assert infos["infant_0"]["touch"]["head"]["object"]


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_lying_infant_feels_its_weight(cone):
    env = free_play_v0.parallel_env(n_agents=1, posture="lying", expressions=False,
                                    touch={"frame": "world"}, physics={"cone": cone})
    env.reset(seed=0)
    obs, _, _, _, infos = rest(env, 150)
    m, d = env.world.model, env.world.data
    mass = m.body_subtreemass[env.world.agents[0].root_body]
    system = skin(env)
    # every skinned side of every contact, as MuJoCo reports it
    f = np.zeros(6)
    expected = 0.0
    for i in range(d.ncon):
        mujoco.mj_contactForce(m, d, i, f)
        expected += f[0] * sum(system.geom_part[g] >= 0 for g in d.contact.geom[i])
    assert system.force_normal.sum() == pytest.approx(expected, rel=0.01)
    # world frame: self-contacts cancel, the floor carries the infant
    F = obs["infant_0"]["touch"].reshape(-1, 3).astype(float).sum(0)
    assert F[2] == pytest.approx(mass * G, rel=0.03)
    assert abs(F[0]) < 0.03 * mass * G and abs(F[1]) < 0.03 * mass * G
    assert all(v["object"] for v in infos["infant_0"]["touch"].values() if not v["self"])


def test_two_infants_hands_pressed_together():
    env = statues([((0.0, 0.0), (0.3, 0.0)), ((0.3, 0.0), (0.0, 0.0))], "standing", HIGH_FIVE)
    system = skin(env)
    hands = ("right_hand", "right_fingers")
    for _ in range(30):                               # the statues settle and lean together
        _, _, _, _, infos = rest(env, 1)
        if all(any(v["agents"] for k, v in infos[a]["touch"].items() if k in hands)
               for a in ("infant_0", "infant_1")):
            break
    else:
        pytest.fail("the right hands never touched")
    for me, other in ((0, 1), (1, 0)):
        touched = infos[f"infant_{me}"]["touch"]
        by_other = {k for k, v in touched.items() if v["agents"]}
        assert by_other and by_other <= set(hands), touched
        for k in by_other:
            assert touched[k] == {"self": False, "agents": [f"infant_{other}"], "object": False}
        geoms = set().union(*(part_geoms(env, me, k) for k in hands))
        others = set().union(*(part_geoms(env, other, k) for k in hands))
        view = system.view(me)
        sensed = sum(view[k]["normal_force"].sum() for k in hands)
        assert sensed == pytest.approx(mujoco_normal(env, geoms, others), rel=0.01)
        assert sensed > 0.1
    # each feels the opposite of what the other feels (world frame)
    F = [sum(system.view(i)[k]["forces"].sum(0) for k in hands) for i in (0, 1)]
    np.testing.assert_allclose(F[0], -F[1], atol=1e-6 * np.linalg.norm(F[0]))


def test_density_scales_point_counts():
    counts = {}
    for density in (0.5, 1.0, 2.0):
        env = free_play_v0.parallel_env(n_agents=1, touch={"density": density})
        c = skin(env).counts("infant_0")
        counts[density] = sum(n for k, n in c.items() if not k.endswith("_eye"))
        assert env.observation_space("infant_0")["touch"].shape == (3 * sum(c.values()),)
    assert counts[1.0] / counts[0.5] == pytest.approx(2.0, rel=0.12)
    assert counts[2.0] / counts[1.0] == pytest.approx(2.0, rel=0.12)
    c = skin(free_play_v0.parallel_env(n_agents=1, touch=True)).counts("infant_0")
    assert c["head"] == pytest.approx(404, rel=0.05)        # the published head: 404 points
    assert c["right_eye"] == 1 and c["left_eye"] == 1
    assert c["right_fingers"] == c["left_fingers"] > 1500
    assert 5000 < sum(c.values()) < 8000


def _lying_pair(**touch):
    """Two infants lying side by side, head to feet, their fingertips touching (0.18 m apart a
    forearm started 4.9 cm inside the other's thigh, which the env refuses)."""
    return free_play_v0.parallel_env(
        n_agents=2, touch=touch or True, expressions=False,
        per_agent=[{"position": (0.0, -0.14), "facing": (1.0, -0.14), "posture": "lying"},
                   {"position": (0.0, 0.14), "facing": (-1.0, 0.14), "posture": "lying"}])


def _rollout(env, seed, steps):
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(steps):
        actions = {a: rng.uniform(-1, 1, env.action_space(a).shape).astype(np.float32)
                   for a in env.agents}
        obs, _, _, _, infos = env.step(actions)
        out.append((np.concatenate([obs[a]["touch"] for a in env.possible_agents]), infos))
    return out


def test_same_seed_same_forces():
    a = _rollout(_lying_pair(), 3, 60)
    b = _rollout(_lying_pair(), 3, 60)
    for (fa, ia), (fb, ib) in zip(a, b):
        np.testing.assert_array_equal(fa, fb)
        assert ia == ib
    assert sum(np.count_nonzero(f) for f, _ in a) > 100
    assert any(v["agents"] for _, infos in a for v in infos["infant_0"]["touch"].values())


def test_nearest_normal_only_and_excluded_parts():
    env = _lying_pair(response="nearest", normal_only=True, exclude=["head"])
    system = skin(env)
    assert "head" not in system.counts("infant_0")
    n = sum(system.counts("infant_0").values())
    assert env.observation_space("infant_0")["touch"].shape == (n,)
    steps = _rollout(env, 5, 40)
    for f, infos in steps:
        assert np.all(f >= 0.0)                       # normal forces only
        assert "head" not in infos["infant_0"]["touch"]
    # nearest: each skinned side of a contact lands on one point, with all its normal force
    sides = system._sides
    assert sides is not None
    assert 0 < np.count_nonzero(system.force_normal) <= len(sides[0])
    assert system.force_normal.sum() == pytest.approx(sides[2].sum(), rel=1e-9)
    assert steps[-1][0].sum() == pytest.approx(system.force_normal.sum(), rel=1e-5)


def test_bad_touch_config_is_rejected():
    with pytest.raises(ConfigError, match=r"touch: density=100.*0\.05 to 8"):
        free_play_v0.parallel_env(n_agents=1, touch={"density": 100})
    with pytest.raises(ConfigError,
                       match=r"(?s)unknown body part.*'tail'.*known parts.*right_hand"):
        free_play_v0.parallel_env(n_agents=1, touch={"exclude": ["tail"]})
    with pytest.raises(ConfigError, match="response"):
        free_play_v0.parallel_env(n_agents=1, touch={"response": "gaussian"})


def test_disk_cache_round_trip(tmp_path, monkeypatch):
    monkeypatch.setenv("MIMO_SOCIAL_CACHE", str(tmp_path / "a"))
    monkeypatch.setattr(skin_module, "_MEMORY", {})
    first = skin(free_play_v0.parallel_env(n_agents=2, touch={"density": 0.7}))
    assert [s.from_cache for s in first.skins] == ["", "memory"]
    files = list((tmp_path / "a" / "skin").glob("*.npz"))
    assert len(files) == 1
    monkeypatch.setattr(skin_module, "_MEMORY", {})
    again = skin(free_play_v0.parallel_env(n_agents=2, touch={"density": 0.7}))
    assert again.skins[0].from_cache == "disk"
    for key in ("points", "normals", "nbr", "nbr_dist", "grid"):
        np.testing.assert_array_equal(getattr(first.skins[0], key), getattr(again.skins[0], key))
    # cache=False neither reads nor writes the disk
    monkeypatch.setenv("MIMO_SOCIAL_CACHE", str(tmp_path / "b"))
    monkeypatch.setattr(skin_module, "_MEMORY", {})
    skin(free_play_v0.parallel_env(n_agents=1, touch={"density": 0.7, "cache": False}))
    assert not (tmp_path / "b").exists()


def test_skin_picture(palm_box, tmp_path):
    env = palm_box[0]
    path = save_skin_png(env, "infant_0", tmp_path / "palm.png",
                         parts=["right_hand", "right_fingers"])
    assert os.path.getsize(path) > 10_000
    with pytest.raises(ValueError, match="tail"):
        save_skin_png(env, "infant_0", tmp_path / "x.png", parts=["tail"])


def test_figure_scene_holds_the_ball():
    env = hand_ball_scene()
    view = skin(env).view(0)
    ball = {env.world.model.geom("ball").id}
    hand = set().union(*(part_geoms(env, 0, k) for k in ("right_hand", "right_fingers")))
    assert mujoco_normal(env, hand, ball) > 0.2
    assert view["right_hand"]["normal_force"].sum() > 0.0
    assert view["right_fingers"]["normal_force"].sum() > 0.0


def test_env_with_touch_pickles():
    import pickle

    env = _lying_pair()
    env.reset(seed=1)
    rest(env, 20)
    twin = pickle.loads(pickle.dumps(env))
    a = _continue(env, 7)
    b = _continue(twin, 7)
    for (fa, ia), (fb, ib) in zip(a, b):
        np.testing.assert_array_equal(fa, fb)
        assert ia == ib
    assert any(np.count_nonzero(f) for f, _ in a)


def _continue(env, seed, steps=15):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(steps):
        actions = {a: rng.uniform(-1, 1, env.action_space(a).shape).astype(np.float32)
                   for a in env.agents}
        obs, _, _, _, infos = env.step(actions)
        out.append((np.concatenate([obs[a]["touch"] for a in env.possible_agents]),
                    [infos[a]["touch"] for a in env.possible_agents]))
    return out


@pytest.mark.parametrize("cone", ["pyramidal", "elliptic"])
def test_contact_forces_decoded_as_mujoco_does(cone):
    env = _lying_pair()
    env.reset(seed=2)
    env.world.model.opt.cone = getattr(mujoco.mjtCone, f"mjCONE_{cone.upper()}")
    rest(env, 30)
    m, d = env.world.model, env.world.data
    system = skin(env)
    ci = np.flatnonzero(d.contact.efc_address[:d.ncon] >= 0)
    assert len(ci) > 5
    expected = np.zeros((len(ci), 3))
    f = np.zeros(6)
    for k, i in enumerate(ci):
        mujoco.mj_contactForce(m, d, int(i), f)
        expected[k] = f[:3]
    for all_dim3 in (True, False):                    # the fast path and the general one
        got = contact_forces(d.contact, ci, d.contact.efc_address[ci], d.efc_force,
                             cone == "pyramidal", all_dim3)
        np.testing.assert_allclose(got, expected, rtol=1e-10, atol=1e-12)


def test_contacts_land_where_they_touched():
    """MuJoCo's contacts come from the pose before the last integration; the skin carries each
    along with its body. With ``nearest``, the point felt is the one nearest to the contact in
    the body's frame at the contact's time (recomputed here by integrating back one step)."""
    env = free_play_v0.parallel_env(n_agents=1, touch={"response": "nearest"})
    env.reset(seed=0)
    m, d = env.world.model, env.world.data
    system = skin(env)
    before = mujoco.MjData(m)
    rng = np.random.default_rng(0)
    u = np.zeros(env.action_space("infant_0")["motors"].shape)
    hits = total = 0
    for k in range(300):
        u = 0.9 * u + 0.1 * rng.uniform(-3, 3, u.shape)          # smooth random movement
        env.step({"infant_0": {"motors": np.clip(u, -1, 1).astype(np.float32),
                               "expression": 0}})
        if k < 100:
            continue
        before.qpos[:] = d.qpos
        mujoco.mj_integratePos(m, before.qpos, d.qvel, -m.opt.timestep)
        mujoco.mj_kinematics(m, before)
        for i in range(d.ncon):
            for g in d.contact.geom[i]:
                p = system.geom_part[g]
                if p < 0 or d.contact.efc_address[i] < 0:
                    continue
                b = m.geom_bodyid[g]
                q = before.xmat[b].reshape(3, 3).T @ (d.contact.pos[i] - before.xpos[b])
                a0, a1 = system.part_start[p], system.part_start[p + 1]
                nearest = a0 + np.argmin(np.linalg.norm(system.points[a0:a1] - q, axis=1))
                hits += system.force_normal[nearest] > 0 or d.efc_force[
                    d.contact.efc_address[i]:d.contact.efc_address[i] + 4].sum() <= 0
                total += 1
    assert total > 500
    assert hits / total > 0.95


@pytest.mark.parametrize("damage", ["short_points", "nbr_out_of_range", "grid_of_another_part",
                                    "nan_normals", "float_counts", "geom_out_of_range"])
def test_a_valid_archive_with_wrong_arrays_is_rebuilt_not_fatal(tmp_path, monkeypatch, damage):
    """A cache file that is a readable archive but whose arrays do not fit together (wrong
    lengths, indices out of range, NaN) is ignored: the skin is computed again, equal to a fresh
    one, and the file is rewritten, so the next env reads a good one from disk."""
    monkeypatch.setenv("MIMO_SOCIAL_CACHE", str(tmp_path))
    monkeypatch.setattr(skin_module, "_MEMORY", {})
    good = skin(free_play_v0.parallel_env(n_agents=1, touch={"density": 0.3})).skins[0]
    (path,) = list((tmp_path / "skin").glob("*.npz"))
    with np.load(path) as z:
        a = {k: z[k].copy() for k in z.files}
    if damage == "short_points":
        a["points"] = a["points"][:-5]
    elif damage == "nbr_out_of_range":
        a["nbr"][3, 0] = len(a["points"]) + 10
    elif damage == "grid_of_another_part":
        a["grid"][0] = len(a["points"]) - 1          # a cell of part 0 naming the last part's point
    elif damage == "nan_normals":
        a["normals"][7] = np.nan
    elif damage == "float_counts":
        a["counts"] = a["counts"].astype(float)
    else:
        a["geom_local"][0] = 99
    np.savez(path, **a)
    monkeypatch.setattr(skin_module, "_MEMORY", {})
    again = skin(free_play_v0.parallel_env(n_agents=1, touch={"density": 0.3})).skins[0]
    assert again.from_cache == ""                    # computed again
    for key in ("points", "normals", "nbr", "grid"):
        np.testing.assert_array_equal(getattr(good, key), getattr(again, key))
    monkeypatch.setattr(skin_module, "_MEMORY", {})
    third = skin(free_play_v0.parallel_env(n_agents=1, touch={"density": 0.3})).skins[0]
    assert third.from_cache == "disk"                # the rewritten file is good


def test_part_velocities_as_mj_comvel():
    """The carry reads each touched body's com velocity as the sum of ``cdof * qvel`` over the
    dofs that move it (MjData only read): the same as ``mujoco.mj_comVel`` computes."""
    import copy

    from mimo_social.senses.contact_forces import body_dofs

    env = _lying_pair()
    env.reset(seed=4)
    _rollout(env, 4, 20)
    m, d = env.world.model, env.world.data
    system = skin(env)
    dofs, on = body_dofs(m, system.part_body)
    q = d.qvel[dofs] * on
    mine = np.einsum("pd,pdk->pk", q, d.cdof[dofs])
    check = copy.copy(d)                              # cdof of the contacts' time, qvel of now
    mujoco.mj_comVel(m, check)
    np.testing.assert_allclose(mine, check.cvel[system.part_body], rtol=1e-12, atol=1e-12)
    assert np.abs(mine).max() > 0.01
