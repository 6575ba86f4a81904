"""The behaviour-cloning warm start's settings (``bc_episodes``, ``bc_epochs``, ``bc_kwargs``):
their defaults and the check that names a bad one (:mod:`~mimo_social.train.demonstrations`
says what each does)."""

from __future__ import annotations

import math
from typing import Any, Mapping

from ..envs.catalog import entry
from .auxiliary import AUX_DEFAULTS, check_aux
from .tasks import TrainInputError

__all__ = ["BC_DEFAULTS", "BC_LOSSES", "BC_ALGOS", "KEEP_UNTIL_MAX", "check_bc"]

#: the settings of ``bc_kwargs`` and their defaults (``epochs``: ``bc_epochs``)
BC_DEFAULTS = {"epochs": 20, "batch_size": 64, "lr": 1e-3, "loss": "mse", "log_std": None,
               "critic_epochs": 0, "keep_updates": 0, "keep_until": 0.5, "dagger_rounds": 0,
               "dagger_episodes": 50, "demonstrator": None, "controller": None,
               "noise": 0.0, "seq_len": 128, "seq_batch": 4, **AUX_DEFAULTS}
BC_LOSSES = ("mse", "nll")
BC_ALGOS = ("ppo", "sac", "recurrent_ppo")
#: the settings a recurrent policy's cloning (by sequences) refuses: they work pair by pair
PAIRWISE = ("dagger_rounds", "critic_epochs", "aux_label")
#: ``keep_until``'s largest value: the kept cloning falls to 0 at this many runs' lengths (at 2
#: it is at half strength at the run's end; at 1000 all but constant)
KEEP_UNTIL_MAX = 1000.0


def check_sequences(algo: str, kwargs: Mapping[str, Any]) -> None:
    """``seq_len`` and ``seq_batch`` (with recurrent_ppo only, integers >= 1) and, with
    recurrent_ppo, none of :data:`PAIRWISE` set; a TrainInputError naming the key otherwise."""
    for key, lo in (("seq_len", 2), ("seq_batch", 1)):
        if key not in kwargs:
            continue
        v = kwargs[key]
        if algo != "recurrent_ppo":
            raise TrainInputError(f"bc_kwargs: {key}={v!r} with algo {algo!r}; allowed: with "
                                  "recurrent_ppo only (its LSTM policy is cloned by sequences)")
        if isinstance(v, bool) or not isinstance(v, int) or v < lo:
            raise TrainInputError(f"bc_kwargs: {key}={v!r}; allowed: an integer >= {lo}")
    if algo == "recurrent_ppo":
        for key in PAIRWISE:
            if kwargs.get(key) not in (None, 0, BC_DEFAULTS[key]):
                raise TrainInputError(
                    f"bc_kwargs: {key}={kwargs[key]!r} with recurrent_ppo; allowed: "
                    f"{BC_DEFAULTS[key]!r} (it works pair by pair; the LSTM policy is cloned by "
                    "sequences)")


def check_bc(task: str, algo: str, mode: str | None, episodes, epochs,
             kwargs: Mapping[str, Any] | None) -> dict | None:
    """The warm start's settings, checked (None: no warm start, ``episodes`` 0); a
    TrainInputError naming the argument, its value and what is allowed otherwise."""
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 0:
        raise TrainInputError(f"bc_episodes={episodes!r}; allowed: an integer >= 0 (scripted "
                              "episodes to clone before training; 0: none)")
    if isinstance(epochs, bool) or not isinstance(epochs, int) or epochs < 1:
        raise TrainInputError(f"bc_epochs={epochs!r}; allowed: an integer >= 1")
    if kwargs is not None and not isinstance(kwargs, Mapping):
        raise TrainInputError(f"bc_kwargs={kwargs!r}; allowed: a dict of "
                              f"{', '.join(k for k in BC_DEFAULTS if k != 'epochs')}")
    kwargs = dict(kwargs or {})
    if episodes == 0:
        if kwargs:
            raise TrainInputError(f"bc_kwargs={kwargs!r} without bc_episodes; allowed: "
                                  "bc_kwargs with bc_episodes >= 1")
        return None
    unknown = sorted(set(kwargs) - set(BC_DEFAULTS) | ({"epochs"} & set(kwargs)))
    if unknown:
        raise TrainInputError(f"bc_kwargs: unknown key(s) {', '.join(unknown)}; allowed: "
                              f"{', '.join(k for k in BC_DEFAULTS if k != 'epochs')} (the "
                              "epochs: bc_epochs)")
    if algo not in BC_ALGOS:
        raise TrainInputError(f"bc_episodes with algo {algo!r}; allowed: {', '.join(BC_ALGOS)}")
    check_sequences(algo, kwargs)
    if mode not in (None, "scripted"):
        raise TrainInputError(f"bc_episodes with --mode {mode}; allowed: one learner (a "
                              "one-agent task, or --mode scripted): the controller drives one "
                              "agent")
    if entry(task).controller is None:
        raise TrainInputError(f"bc_episodes: {task} has no scripted controller (catalogue "
                              "entry: controller=None); allowed: tasks with one")
    s = {**BC_DEFAULTS, **kwargs, "epochs": epochs, "episodes": episodes}
    bs = s["batch_size"]
    if isinstance(bs, bool) or not isinstance(bs, int) or bs < 1:
        raise TrainInputError(f"bc_kwargs: batch_size={bs!r}; allowed: an integer >= 1")
    lr = s["lr"]
    if isinstance(lr, bool) or not isinstance(lr, (int, float)) or not 0 < lr < math.inf:
        raise TrainInputError(f"bc_kwargs: lr={lr!r}; allowed: a number > 0")
    if s["loss"] not in BC_LOSSES or (algo == "sac" and s["loss"] != "mse"):
        allowed = "mse" if algo == "sac" else ", ".join(BC_LOSSES)
        raise TrainInputError(f"bc_kwargs: loss={s['loss']!r}; allowed with {algo}: {allowed}")
    ls = s["log_std"]
    values = ls if isinstance(ls, (list, tuple)) else [ls]
    if ls is not None and (algo not in ("ppo", "recurrent_ppo") or not values or any(
            isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
            for v in values)):
        raise TrainInputError(f"bc_kwargs: log_std={ls!r}; allowed: None, or with ppo (or "
                              "recurrent_ppo) a finite number or a non-empty list of them, one "
                              "per action dimension (the Gaussian's log-std after cloning)")
    if isinstance(ls, tuple):
        s["log_std"] = list(ls)
    ce = s["critic_epochs"]
    if isinstance(ce, bool) or not isinstance(ce, int) or ce < 0 or (ce and algo != "ppo"):
        raise TrainInputError(f"bc_kwargs: critic_epochs={ce!r}; allowed: an integer >= 0 "
                              "(> 0 with ppo only: epochs fitting its value function to the "
                              "demonstrations' returns)")
    nz = s["noise"]
    if isinstance(nz, bool) or not isinstance(nz, (int, float)) or not 0 <= nz <= 1:
        raise TrainInputError(f"bc_kwargs: noise={nz!r}; allowed: a number in [0, 1] (the sd "
                              "of the Gaussian noise on a Box action, the chance of a random "
                              "choice of a Discrete one, while the demonstrations play; 0: none)")
    s["noise"] = float(nz)
    check_aux(s, algo)
    for key in ("dagger_rounds", "dagger_episodes"):
        v = s[key]
        if isinstance(v, bool) or not isinstance(v, int) or v < (key == "dagger_episodes"):
            raise TrainInputError(f"bc_kwargs: {key}={v!r}; allowed: an integer >= "
                                  f"{int(key == 'dagger_episodes')} (DAgger: rounds of the "
                                  "cloned policy's episodes labelled by the controller)")
    ku, kt = s["keep_updates"], s["keep_until"]
    if isinstance(ku, bool) or not isinstance(ku, int) or ku < 0:
        raise TrainInputError(f"bc_kwargs: keep_updates={ku!r}; allowed: an integer >= 0 "
                              "(behaviour-cloning minibatches after each RL update; 0: none)")
    if isinstance(kt, bool) or not isinstance(kt, (int, float)) or not 0 < kt <= KEEP_UNTIL_MAX:
        raise TrainInputError(f"bc_kwargs: keep_until={kt!r}; allowed: a number in (0, "
                              f"{KEEP_UNTIL_MAX:g}] (the share of the run over which "
                              "keep_updates falls to 0; beyond 1 it is still on at the end)")
    dn = s["demonstrator"]
    if dn is not None and (not isinstance(dn, str) or dn not in entry(task).demonstrator_names()):
        raise TrainInputError(f"bc_kwargs: demonstrator={dn!r}; allowed for {task}: None (the "
                              f"task's controller) or one of "
                              f"{list(entry(task).demonstrator_names())}")
    cls = entry(task).controller_class(dn)
    ck = s["controller"]
    if ck is not None:
        if not isinstance(ck, Mapping) or not all(isinstance(k, str) for k in ck):
            raise TrainInputError(f"bc_kwargs: controller={ck!r}; allowed: None or a dict of "
                                  f"{cls.__name__}'s keyword arguments")
        try:
            cls(**ck)
        except (TypeError, ValueError) as e:
            raise TrainInputError(f"bc_kwargs: controller={dict(ck)!r} not allowed: {e}") from None
        s["controller"] = dict(ck)
    return s
