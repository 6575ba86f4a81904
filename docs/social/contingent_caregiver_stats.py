"""Response statistics of ContingentCaregiver, as docs/social/contingent_caregiver.md gives them.

Run from the repository root: `MUJOCO_GL=egl python docs/social/contingent_caregiver_stats.py`
(about a minute). It uses the small face-to-face test task of tests/partners/test_contingent.py."""
import sys, time
import numpy as np
sys.path.insert(0, "tests/partners")
from test_contingent import (ADULT, ADULT_POS, HAPPY, NEUTRAL, ContingentCaregiver, face_env,
                             learner_cues, run, _reach_pose)

BODIES = {"adult, spring-damper": ADULT, "adult, positional": ADULT_POS, "18-month-old": {}}
FLOOR = np.array([0.3, 0.25, 0.0])
for name, body in BODIES.items():
    for prob in (0.3, 0.6, 1.0):       # 200 smile onsets, delay 0.1 s
        p = ContingentCaregiver(cues=("expression",), delay_s=0.1, probability=prob,
                                duration_s=0.05)
        faces, _ = run(face_env(p, body), lambda k, lr: lr.face_only(
            HAPPY if k % 20 < 5 else NEUTRAL), 4000)
        on = np.flatnonzero((faces[1:, 1] == HAPPY) & (faces[:-1, 1] != HAPPY)) + 1
        ans = np.array([e["answered"] for e in p.events])
        lat = on - 20 * np.flatnonzero(ans)
        print(f"{name}: p={prob}: {ans.sum()}/{len(ans)} answered; latencies (steps) "
              f"{sorted(set(lat.tolist()))} (delay_steps {p.delay_steps})")
    # gaze: the learner looks at a floor point for 1.5 s; the caregiver follows for 1.5 s
    p = ContingentCaregiver(cues=("gaze",), delay_s=0.2, duration_s=1.5)
    env = face_env(p, body)
    care = env.unwrapped.possible_agents[1]     # caregiver_0 (an adult) or infant_1
    log = {}
    spent = []
    inner_act = p.act

    def timed(*a):
        t0 = time.perf_counter()
        out = inner_act(*a)
        spent.append(time.perf_counter() - t0)
        return out
    p.act = timed
    run(env, lambda k, lr: lr.looking_at(FLOOR) if 100 <= k < 250 else lr.at_face(), 400,
        after=lambda k: log.__setitem__(k, (learner_cues(env.unwrapped, care, "infant_0"),
                                            learner_cues(env.unwrapped, "infant_0", care))))
    ms = np.median(spent) * 1e3
    s = p.responses[0]["step"]
    err = {k: np.linalg.norm(c.gaze_point[:2] - lr_.gaze_point[:2]) if c.gaze_point is not None
           and lr_.gaze_point is not None else np.inf for k, (c, lr_) in log.items()}
    within = next(k for k in range(s, 400) if err[k] < 0.05) - s
    end = s + p.duration_steps
    back = next(k for k in range(end, 400) if log[k][0].gaze_on_face) - end
    print(f"{name}: gaze event step {p.events[0]['step']}, response {s}; caregiver's floor point "
          f"within 5 cm of the learner's after {within} steps, {err[245] * 100:.1f} cm at step 245; back on the learner's face {back} steps after; mean angle on face before "
          f"{np.mean([log[k][0].gaze_angle_deg for k in range(60, 100)]):.2f} deg; "
          f"{ms:.2f} ms per act() (median)")
    # still: switch 5 steps into the caregiver's first gaze response (its head turning)
    p = ContingentCaregiver(delay_s=0.1, duration_s=0.5)
    env = face_env(p, body)
    sw = []

    def switch(k):
        if not sw and any(r["cue"] == "gaze" and k == r["step"] + 5 for r in p.responses):
            sw.append(k)
            p.set_mode("still")
    faces, qs = run(env, lambda k, lr: (lr.looking_at(FLOOR, HAPPY if k % 30 < 10 else 0)
                                        if k % 120 < 60 else lr.at_face(HAPPY if k % 30 < 10 else 0)),
                    300, after=switch)
    k0 = sw[0]
    over = np.degrees(np.abs(qs[k0:] - qs[k0]).max())
    drift = np.degrees(np.abs(qs[k0 + 50:] - qs[k0 + 50]).max())
    print(f"{name}: still from step {k0}: faces neutral {np.all(faces[k0:, 1] == 0)}, responses "
          f"after {sum(r['step'] >= k0 for r in p.responses)}; joints move up to {over:.2f} deg "
          f"after the switch, {drift:.3f} deg from 0.5 s on")
# the pat (kneeling adult 0.3 m away, leaning 15 deg)
for name, body in list(BODIES.items())[:2]:
    p = ContingentCaregiver(cues=("touch",), delay_s=0.2, duration_s=1.0)
    env = face_env(p, body, distance=0.3, lean=15.0)
    env.reset(seed=0)
    reach = _reach_pose(env, "caregiver_0/left_upper_leg")
    w = env.unwrapped.world
    arm = [w.model.geom(f"infant_0/right_{g}").id for g in ("lower_arm", "upper_arm")]
    dist = []
    run(env, lambda k, lr: lr.at_face(arm=reach if 50 <= k < 200 else None), 220,
        after=lambda k: dist.append(min(np.linalg.norm(w.data.site_xpos[w.agents[1].palm_sites][:, None]
                                                       - w.data.geom_xpos[arm][None], axis=2).min(),
                                        9)))
    s = p.responses[0]["step"]
    print(f"{name}: pat: event {p.events[0]['step']}, start {s}; palm to the learner's arm "
          f"{dist[s] * 100:.0f} cm at the start, {min(dist[s:s + p.duration_steps]) * 100:.0f} cm "
          f"nearest; plan misses {np.round(p.pat_misses, 3)} m")
# non-contingent: 20 s interactive (smile every 0.5 s, p 0.5), then 20 s non-contingent
p = ContingentCaregiver(cues=("expression",), delay_s=0.0, probability=0.5, duration_s=0.05)
run(face_env(p), lambda k, lr: lr.face_only(HAPPY if k % 50 < 5 else NEUTRAL), 4000,
    after=lambda k: k == 2000 and p.set_mode("non_contingent"))
n0 = sum(r["step"] < 2000 for r in p.responses)
print(f"non-contingent: measured {p.measured_rates['expression']:.2f} /s ({n0} in 20 s); "
      f"then {sum(r['step'] >= 2000 for r in p.responses)} in 20 s")
