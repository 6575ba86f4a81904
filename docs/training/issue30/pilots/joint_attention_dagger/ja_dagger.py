"""Pilot (issue 30, thirteenth session): DAgger rounds on a joint-attention clone.

The twelfth session's clone (``../joint_attention_checking_clone/ja_checking_clone.py``: the
demonstrations, every k-th pair, the epochs at lr 3e-4, the same seeds), measured on seeds
1000.. as there; then the package's DAgger (``mimo_social.train.dagger.dagger``: the clone plays
``dagger_episodes`` episodes a round, the demonstrator labels every state it meets, all pairs
so far cloned ``dagger_epochs`` epochs; the best play's policy kept) and the kept policy
measured on the same seeds.

Arguments: demonstrator, episodes, k, epochs, DART noise, episodes played, fovea, field of view
(degrees), DAgger rounds, DAgger episodes a round, epochs a round.
"""
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "joint_attention_checking_clone"))

from ja_checking_clone import clone_epochs, evaluate, record, setup  # noqa: E402

from mimo_social.train.bc_settings import BC_DEFAULTS  # noqa: E402
from mimo_social.train.dagger import dagger  # noqa: E402


def main():
    name, episodes, every, epochs = sys.argv[1], *map(int, sys.argv[2:5])
    noise, play, fovea, fov = float(sys.argv[5]), int(sys.argv[6]), *map(float, sys.argv[7:9])
    rounds, per_round, round_epochs = map(int, sys.argv[9:12])
    env, model = setup(fovea, fov)
    t0 = time.time()
    demos = record(env, name, episodes, every, noise, t0)
    clone_epochs(model, demos, epochs, t0)
    tag = f"{name}_fov{fov:g}_fovea{fovea:g}"
    model.save(f"/tmp/ja_dagger_{tag}_clone.zip")
    wins = evaluate(model, env, name, play)
    print(f"clone of {name}: {wins} / {play}, {time.time() - t0:.0f} s", flush=True)
    settings = {**BC_DEFAULTS, "epochs": round_epochs, "lr": 3e-4, "dagger_rounds": rounds,
                "dagger_episodes": per_round, "demonstrator": name}
    demos, plays = dagger(model, "joint_attention", env, demos, settings, 0,
                          report=lambda line: print(f"{line}, {time.time() - t0:.0f} s",
                                                    flush=True))
    for p in plays:
        print(f"  {p}", flush=True)
    model.save(f"/tmp/ja_dagger_{tag}_dagger.zip")
    wins = evaluate(model, env, name, play)
    print(f"after DAgger ({rounds} rounds of {per_round} episodes, {round_epochs} epoch(s) "
          f"each): {wins} / {play}, {time.time() - t0:.0f} s")


if __name__ == "__main__":
    main()
