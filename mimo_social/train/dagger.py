"""DAgger after the behaviour-cloning warm start (``bc_kwargs`` ``dagger_rounds``; issue 30).

Cloning the scripted controller's episodes teaches the policy the states the controller visits;
the cloned policy drifts off them and has never seen what to do there (on social touch the
controller succeeds in 98 % of its episodes and the policy cloned from 100 of them in 60 %).
The controller can be asked anywhere, since it acts on the world's state: in each round the
cloned policy (its mean action) plays ``dagger_episodes`` episodes, every observation it meets
is labelled with the controller's action there, the pairs join the demonstrations and the
policy is cloned again on all of them (Ross, Gordon & Bagnell 2011, with the learner's policy
alone from the first round on). The controller is reset with each episode, so its plan for the
episode (a target posture, a phase) is the one it would have made from that start.

Each round's episodes are seeded ``DAGGER_SEED + seed + 1000 * round + k``; after the last
round the last policy plays once more (labelled, not cloned again), and the policy kept for RL
is the one whose play succeeded most (then: the highest return): the rounds do not improve
monotonically (measured on handover, 6 rounds: 0, 6, 60, 62, 14, 98 %). ``config.json`` records
per play the policy's success rate and mean return on its episodes (a measure of the cloning
before RL, on seeds of its own), the pairs added and which policy was kept.
"""

from __future__ import annotations

from typing import Any, Mapping

from .demonstrations import Demonstrations, Demonstrator, clone, demonstrator, play

__all__ = ["DAGGER_SEED", "Labeller", "dagger"]

DAGGER_SEED = 30_000


class Labeller(Demonstrator):
    """The model's mean action plays; the controller labels each observation it meets."""

    def __init__(self, controller_cls, env, model, aux_label: str | None = None):
        super().__init__(controller_cls, env, aux_label=aux_label)
        self.model = model

    def act(self, env, agent: str, obs):
        super().act(env, agent, obs)                  # the controller's label, recorded
        action, _ = self.model.predict(obs, deterministic=True)
        return action


def dagger(model, task: str, env, demos: Demonstrations, settings: Mapping[str, Any],
           seed: int, report=None) -> tuple[Demonstrations, list[dict]]:
    """``settings["dagger_rounds"]`` rounds of DAgger on ``env`` (module docstring), each
    cloning ``settings["epochs"]`` epochs on all the pairs so far, then one more play of the
    last policy (labelled too, not cloned); the policy kept is the one of the play with the
    highest success rate (then return), as DAgger's guarantee is for the best of its policies.
    Returns the pairs and a record per play (``kept`` marks the policy kept); ``report`` (a
    function of a line of text, optional) hears of each play as it ends (a warm start can take
    most of an hour)."""
    import copy

    controller = demonstrator(task, settings)
    rounds, best = [], None
    for r in range(int(settings["dagger_rounds"]) + 1):
        first = DAGGER_SEED + int(seed) + 1000 * r
        played = play(Labeller(controller, env, model, settings.get("aux_label")), env, first,
                      int(settings["dagger_episodes"]))
        demos = demos.joined(played)
        measured = played.summary()
        score = (measured["success_rate"] or 0.0, measured["return_mean"])
        if best is None or score > best[0]:
            best = (score, copy.deepcopy(model.policy.state_dict()), r)
        record = {"round": r + 1, "seeds": measured["seeds"],
                  "success_rate": measured["success_rate"],
                  "return_mean": measured["return_mean"], "pairs_added": len(played),
                  "pairs": len(demos)}
        if report is not None:
            rate = measured["success_rate"]
            report(f"DAgger play {r + 1} of {int(settings['dagger_rounds']) + 1}: the policy "
                   + ("" if rate is None else f"{rate:.0%} on its ")
                   + f"{int(settings['dagger_episodes'])} episodes, return "
                   f"{measured['return_mean']:.1f}; {len(demos)} pairs")
        if r < int(settings["dagger_rounds"]):
            res = clone(model, demos, int(settings["epochs"]), int(settings["batch_size"]),
                        float(settings["lr"]), str(settings["loss"]), int(seed) + r + 1,
                        settings["log_std"], float(settings.get("aux_weight", 1.0)))
            record["loss_after"] = res["loss_after"]
            if "aux_accuracy_after" in res:
                record["aux_accuracy_after"] = res["aux_accuracy_after"]
        rounds.append(record)
    model.policy.load_state_dict(best[1])
    for record in rounds:
        record["kept"] = record["round"] == best[2] + 1
    return demos, rounds
