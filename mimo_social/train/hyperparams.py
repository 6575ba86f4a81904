"""Per-task, per-algorithm hyperparameters as data, and the check of every ``--algo-kwargs`` key.

The values ship as TOML files in ``mimo_social/train/hyperparams/``: ``default.toml`` (SB3's
defaults, written out) and one ``<task>.toml`` per task, each with an ``[<algo>]`` table
(``ppo``, ``sac``, ``recurrent_ppo``), optional per-mode tables ``[<algo>.<mode>]`` (``shared``,
``independent``, ``scripted``) and an optional ``[run]`` table of ``train`` options
(``normalize_obs``). Every value carries its provenance as a TOML comment
(docs/hyperparameters.md lists them all).

* :func:`load`: the shipped values of a task, algorithm and mode (default <- task <- mode);
* :func:`resolve`: the values a run uses: the shipped ones overridden by the caller's
  (``--algo-kwargs``), with where each came from; checked by :func:`validate`;
* :func:`validate`: unknown keys (against the SB3 class's and its policy's signatures, with a
  "did you mean"; ``recurrent_ppo``: ``RecurrentPPO`` and its ``MlpLstmPolicy``, so
  ``lstm_hidden_size``, ``n_lstm_layers``, ``shared_lstm``, ``enable_critic_lstm``,
  ``lstm_kwargs``) and values that are cheap to check raise :class:`TrainInputError`;
* :func:`to_sb3` / :func:`to_json`: TOML/JSON-friendly values (``"tanh"``, ``"lin_3e-4"``) to SB3
  objects (``torch.nn.Tanh``, a linear schedule) and back (for ``config.json``);
* :func:`run_options`, :func:`markdown_table`.

``policy_kwargs`` merges key by key (a command-line ``{"policy_kwargs": {"net_arch": [32]}}``
keeps the shipped ``activation_fn``); every other key is replaced whole.
"""

from __future__ import annotations

import difflib
import functools
import inspect
import math
import re
import tomllib
from importlib import resources
from typing import Any, Callable, Mapping

from ..envs.catalog import CATALOG
from .tasks import ALGOS, MODES, TrainInputError, algo_class, check_algo

__all__ = ["DIRECTORY", "RUNNER_KEYS", "ACTIVATIONS", "OPTIMIZERS", "COMMAND_LINE", "CHECKS",
           "POLICIES", "TITLES",
           "LinearSchedule", "shipped_files", "load", "resolve", "validate", "allowed_keys",
           "allowed_policy_keys", "to_sb3", "to_json", "run_options", "notes",
           "markdown_table"]

#: the folder of the TOML files (a Traversable; tests may point it elsewhere)
DIRECTORY = resources.files(__package__) / "hyperparams"
#: keyword arguments ``train`` sets itself: never taken from a file or ``--algo-kwargs``
RUNNER_KEYS = {"policy": "train uses MlpPolicy", "env": "train builds the task's env",
               "seed": "use --seed", "device": "train runs on the CPU",
               "verbose": "use --verbose"}
#: activation names (TOML/JSON) -> torch.nn class names
ACTIVATIONS = {"tanh": "Tanh", "relu": "ReLU", "elu": "ELU", "leaky_relu": "LeakyReLU",
               "gelu": "GELU", "silu": "SiLU", "sigmoid": "Sigmoid", "softplus": "Softplus",
               "identity": "Identity"}
#: optimizer names -> torch.optim class names
OPTIMIZERS = {"adam": "Adam", "adamw": "AdamW", "rmsprop": "RMSprop", "sgd": "SGD"}
#: provenance of a value given by the caller
COMMAND_LINE = "command line"
#: the keys that may be a schedule (a number, "lin_<start>", or a callable), per algorithm
SCHEDULES = {"ppo": ("learning_rate", "clip_range", "clip_range_vf"), "sac": ("learning_rate",),
             "recurrent_ppo": ("learning_rate", "clip_range", "clip_range_vf")}
#: the sub-network keys of a dict net_arch
NET_ARCH_KEYS = {"ppo": ("pi", "vf"), "sac": ("pi", "qf"), "recurrent_ppo": ("pi", "vf")}
#: the policy whose ``__init__`` says which ``policy_kwargs`` keys an algorithm takes
POLICIES = {"ppo": "MlpPolicy", "sac": "MlpPolicy", "recurrent_ppo": "MlpLstmPolicy"}
#: an algorithm's name in docs/hyperparameters.md's table
TITLES = {"ppo": "PPO", "sac": "SAC", "recurrent_ppo": "RecurrentPPO"}
_LIN = re.compile(r"^lin_(.+)$")
_TABLES = (*ALGOS, "run")
_RUN_OPTIONS = {"normalize_obs": bool}


class LinearSchedule:
    """SB3 schedule from ``start`` down to 0 over the run (``progress_remaining`` goes 1 -> 0);
    written ``"lin_<start>"`` (as RL Baselines3 Zoo writes it)."""

    def __init__(self, start: float):
        self.start = float(start)

    def __call__(self, progress_remaining: float) -> float:
        return progress_remaining * self.start

    def __repr__(self) -> str:
        return f"lin_{self.start!r}"

    def __eq__(self, other) -> bool:
        return isinstance(other, LinearSchedule) and other.start == self.start

    def __hash__(self) -> int:
        return hash(("lin", self.start))


# ---------------------------------------------------------------- the files

def shipped_files() -> list[str]:
    """The TOML files' names (``default.toml`` and one per task that has one)."""
    return sorted(p.name for p in DIRECTORY.iterdir() if p.name.endswith(".toml"))


@functools.lru_cache(maxsize=64)
def _parse(name: str, text: str) -> dict:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise TrainInputError(f"{name}: not valid TOML ({exc})") from None
    bad = sorted(set(data) - set(_TABLES))
    if bad:
        raise TrainInputError(f"{name}: unknown table(s) {', '.join(bad)}; allowed: "
                              f"{', '.join(_TABLES)}")
    return data


def _file(name: str) -> dict:
    """A shipped file's tables ({} if there is no such file); a fresh copy each call."""
    if not (DIRECTORY / name).is_file():
        return {}
    return _copy(_parse(name, (DIRECTORY / name).read_text()))


def _copy(value):
    if isinstance(value, dict):
        return {k: _copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_copy(v) for v in value]
    return value


def _task_file(task: str) -> str:
    names = [e.name for e in CATALOG]
    if task not in names:
        raise TrainInputError(f"task {task!r} not allowed; allowed: {', '.join(names)}")
    return f"{task}.toml"


def _check_mode(mode: str | None) -> None:
    if mode is not None and mode not in MODES:
        raise TrainInputError(f"mode {mode!r} not allowed; allowed: {', '.join(MODES)}")


def _layers(task: str, algo: str, mode: str | None) -> list[tuple[str, dict]]:
    """(provenance, values) from lowest to highest precedence."""
    check_algo(algo)
    _check_mode(mode)
    out = []
    for name in ("default.toml", _task_file(task)):
        table = _file(name).get(algo, {})
        out.append((f"shipped:{name}", {k: v for k, v in table.items() if k not in MODES}))
        if mode is not None and isinstance(table.get(mode), dict):
            out.append((f"shipped:{name} [{algo}.{mode}]", table[mode]))
    return out


def _merge(kwargs: dict, prov: dict, layer: Mapping[str, Any], source: str) -> None:
    """``layer`` on top of ``kwargs`` (``policy_kwargs`` key by key), noting each key's source."""
    for key, value in layer.items():
        if key == "policy_kwargs":
            base = kwargs.get(key) if isinstance(kwargs.get(key), dict) else {}
            if isinstance(value, Mapping):
                kwargs[key] = {**base, **_copy(dict(value))}
                prov.update({f"policy_kwargs.{k}": source for k in value})
                continue
            for k in [k for k in prov if k.startswith("policy_kwargs.")]:
                del prov[k]
        kwargs[key] = _copy(value)
        prov[key] = source


def _load(task: str, algo: str, mode: str | None) -> tuple[dict, dict]:
    kwargs, prov = {}, {}
    for source, layer in _layers(task, algo, mode):
        _merge(kwargs, prov, layer, source)
    return kwargs, prov


def load(task: str, algo: str, mode: str | None = None) -> dict:
    """The shipped values of ``task`` (any catalogue task; one without a file gets
    ``default.toml``'s) for ``algo``, with the ``[<algo>.<mode>]`` tables of ``mode`` on top.
    TOML-friendly values (see :func:`to_sb3`)."""
    return _load(task, algo, mode)[0]


def run_options(task: str, mode: str | None = None) -> dict:
    """The ``[run]`` table of ``task`` (``train`` options, e.g. ``{"normalize_obs": True}``)
    over ``default.toml``'s; ``[run.<mode>]`` on top. Not SB3 arguments."""
    _check_mode(mode)
    out = {}
    for name in ("default.toml", _task_file(task)):
        table = _file(name).get("run", {})
        out.update({k: v for k, v in table.items() if k not in MODES})
        if mode is not None and isinstance(table.get(mode), dict):
            out.update(table[mode])
    for key, value in out.items():
        if key not in _RUN_OPTIONS:
            raise TrainInputError(f"[run] {key!r} unknown; allowed: {', '.join(_RUN_OPTIONS)}")
        if not isinstance(value, _RUN_OPTIONS[key]):
            raise TrainInputError(f"[run] {key}={value!r}: must be true or false")
    return out


def resolve(task: str, algo: str, given: Mapping[str, Any] | None = None,
            mode: str | None = None, steps: int | None = None) -> tuple[dict, dict]:
    """``(kwargs, provenance)``: the values a run uses, the shipped ones (:func:`load`)
    overridden by ``given`` (the command line's ``--algo-kwargs``), validated
    (:func:`validate`; raises :class:`TrainInputError` before anything is built).
    ``provenance`` maps every key (``policy_kwargs.<key>`` for those of ``policy_kwargs``) to
    ``"shipped:<file>"`` or ``"command line"``. SAC's shipped ``buffer_size`` is capped at
    ``steps`` (it never holds more); a given one is used as it is. Values stay TOML/JSON-friendly:
    pass ``to_sb3(algo, kwargs)`` to SB3 and ``to_json(kwargs)`` to ``config.json``."""
    if given is not None and not isinstance(given, Mapping):
        raise TrainInputError(f"--algo-kwargs must be a JSON object, got {given!r}")
    given = dict(given or {})
    kwargs, prov = _load(task, algo, mode)
    _merge(kwargs, prov, given, COMMAND_LINE)
    if algo == "sac" and steps is not None and prov.get("buffer_size", "").startswith("shipped"):
        if _is_int(steps) and steps > 0 and _is_int(kwargs.get("buffer_size")) \
                and steps < kwargs["buffer_size"]:
            kwargs["buffer_size"] = int(steps)
            prov["buffer_size"] += ", capped at steps"
    validate(algo, kwargs, provenance=prov)
    return kwargs, prov


# ---------------------------------------------------------------- checks

def _is_int(v) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _check(test: Callable[[Any], bool], allowed: str) -> Callable[[Any], str | None]:
    return lambda v: None if test(v) else allowed


_POS_INT = _check(lambda v: _is_int(v) and v > 0, "a positive integer")
_NONNEG_INT = _check(lambda v: _is_int(v) and v >= 0, "an integer >= 0")
_POS_NUM = _check(lambda v: _is_num(v) and v > 0, "a positive number")
_NONNEG_NUM = _check(lambda v: _is_num(v) and v >= 0, "a number >= 0")
_UNIT = _check(lambda v: _is_num(v) and 0 <= v <= 1, "a number in [0, 1]")
_UNIT_OPEN0 = _check(lambda v: _is_num(v) and 0 < v <= 1, "a number in (0, 1]")
_BOOL = _check(lambda v: isinstance(v, bool), "true or false")
_DICT = _check(lambda v: v is None or isinstance(v, Mapping), "an object (dict)")
_STR = _check(lambda v: v is None or isinstance(v, str), "a string")
_CLASS = _check(lambda v: v is None or inspect.isclass(v), "a class (Python callers only)")
_ANY_NUM = _check(_is_num, "a number")


def _lin_start(v) -> float | None:
    m = _LIN.match(v) if isinstance(v, str) else None
    if m is None:
        return None
    try:
        start = float(m.group(1))
    except ValueError:
        return None
    return start if math.isfinite(start) and start > 0 else None


def _schedule(v) -> str | None:
    if (_is_num(v) and v > 0) or _lin_start(v) is not None or isinstance(v, LinearSchedule) \
            or (callable(v) and not isinstance(v, str)):
        return None
    return ('a positive number, "lin_<start>" (e.g. "lin_3e-4": linear from start to 0 over '
            'the run) or a callable of progress_remaining (Python callers)')


def _optional(check):
    return lambda v: None if v is None else check(v)


def _train_freq(v) -> str | None:
    ok = (_is_int(v) and v > 0) or (isinstance(v, (list, tuple)) and len(v) == 2
                                     and _is_int(v[0]) and v[0] > 0
                                     and v[1] in ("step", "episode"))
    return None if ok else 'a positive integer or [n, "step" | "episode"]'


def _sac_ent_coef(v) -> str | None:
    if (_is_num(v) and v >= 0) or v == "auto":
        return None
    if isinstance(v, str) and v.startswith("auto_"):
        try:
            if float(v[5:]) > 0:
                return None
        except ValueError:
            pass
    return 'a number >= 0, "auto" or "auto_<initial value>" (e.g. "auto_0.1")'


def _target_entropy(v) -> str | None:
    return None if v == "auto" or _is_num(v) else 'a number or "auto"'


def _gradient_steps(v) -> str | None:
    ok = _is_int(v) and (v > 0 or v == -1)
    return None if ok else "a positive integer, or -1 (as many as env steps per rollout)"


_COMMON = {"learning_rate": _schedule, "gamma": _UNIT, "batch_size": _POS_INT, "use_sde": _BOOL,
           "sde_sample_freq": _check(lambda v: _is_int(v) and v >= -1, "an integer >= -1"),
           "stats_window_size": _POS_INT, "tensorboard_log": _STR, "policy_kwargs": _DICT}
_PPO = {**_COMMON, "n_steps": _POS_INT, "n_epochs": _POS_INT, "gae_lambda": _UNIT,
        "clip_range": _schedule, "clip_range_vf": _optional(_schedule),
        "normalize_advantage": _BOOL, "ent_coef": _NONNEG_NUM, "vf_coef": _NONNEG_NUM,
        "max_grad_norm": _POS_NUM, "target_kl": _optional(_POS_NUM)}
CHECKS = {
    "ppo": {**_PPO, "rollout_buffer_class": _CLASS, "rollout_buffer_kwargs": _DICT},
    "recurrent_ppo": dict(_PPO),
    "sac": {**_COMMON, "buffer_size": _POS_INT, "learning_starts": _NONNEG_INT,
            "tau": _UNIT_OPEN0, "train_freq": _train_freq, "gradient_steps": _gradient_steps,
            "replay_buffer_class": _CLASS, "replay_buffer_kwargs": _DICT,
            "optimize_memory_usage": _BOOL, "n_steps": _POS_INT, "ent_coef": _sac_ent_coef,
            "target_update_interval": _POS_INT, "target_entropy": _target_entropy,
            "use_sde_at_warmup": _BOOL},
}


def _net_arch(algo: str):
    keys = NET_ARCH_KEYS[algo]

    def layers(v) -> bool:
        return isinstance(v, (list, tuple)) and all(_is_int(n) and n > 0 for n in v)

    def check(v) -> str | None:
        if layers(v) or (isinstance(v, Mapping) and v and set(v) <= set(keys)
                         and all(layers(x) for x in v.values())):
            return None
        return (f"a list of layer sizes (e.g. [64, 64]) or an object with "
                f"{' and '.join(keys)} lists (e.g. {{{keys[0]!r}: [64, 64], "
                f"{keys[1]!r}: [64, 64]}})")
    return check


def _named_class(names: Mapping[str, str], base: str):
    def check(v) -> str | None:
        if (isinstance(v, str) and v in names) or inspect.isclass(v):
            return None
        return f"one of {', '.join(repr(n) for n in names)} (or a {base} class, Python callers)"
    return check


def _policy_checks(algo: str) -> dict:
    return {"lstm_hidden_size": _POS_INT, "n_lstm_layers": _POS_INT, "shared_lstm": _BOOL,
            "enable_critic_lstm": _BOOL, "lstm_kwargs": _DICT, "net_arch": _net_arch(algo),
            "activation_fn": _named_class(ACTIVATIONS, "torch.nn.Module"),
            "optimizer_class": _named_class(OPTIMIZERS, "torch.optim.Optimizer"),
            "optimizer_kwargs": _DICT, "ortho_init": _BOOL, "use_sde": _BOOL,
            "log_std_init": _ANY_NUM, "full_std": _BOOL, "use_expln": _BOOL,
            "squash_output": _BOOL, "clip_mean": _POS_NUM, "n_critics": _POS_INT,
            "features_extractor_class": _CLASS, "features_extractor_kwargs": _DICT,
            "share_features_extractor": _BOOL, "normalize_images": _BOOL}


def _parameters(fn, skip: tuple[str, ...]) -> list[str]:
    return [n for n, p in inspect.signature(fn).parameters.items()
            if n not in skip and not n.startswith("_")
            and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]


def allowed_keys(algo: str) -> list[str]:
    """The keyword arguments of the algorithm's SB3 class that a file or ``--algo-kwargs`` may
    set (its ``__init__`` minus :data:`RUNNER_KEYS`)."""
    return _parameters(algo_class(algo).__init__, ("self", *RUNNER_KEYS))


def allowed_policy_keys(algo: str) -> list[str]:
    """The keys of ``policy_kwargs``: the ``MlpPolicy`` class's (``recurrent_ppo``:
    ``MlpLstmPolicy``'s) ``__init__`` arguments minus those SB3 passes itself."""
    policy = algo_class(algo).policy_aliases[POLICIES[check_algo(algo)]]
    return _parameters(policy.__init__,
                       ("self", "observation_space", "action_space", "lr_schedule"))


def _unknown(key: str, allowed: list[str], what: str, where: str,
             note: str = "") -> TrainInputError:
    close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.6)
    hint = f"; did you mean {close[0]!r}?" if close else ""
    return TrainInputError(f"{where}: unknown {what} {key!r}{note}{hint} allowed: "
                           f"{', '.join(allowed)}" if hint else
                           f"{where}: unknown {what} {key!r}{note}; allowed: "
                           f"{', '.join(allowed)}")


def _where(prov: Mapping[str, str] | None, key: str) -> str:
    source = (prov or {}).get(key, COMMAND_LINE)
    if source == COMMAND_LINE:
        return "--algo-kwargs"
    return f"mimo_social/train/hyperparams/{source.split(':', 1)[1]}"


def validate(algo: str, kwargs: Mapping[str, Any],
             provenance: Mapping[str, str] | None = None) -> None:
    """Raise :class:`TrainInputError` for a key the SB3 class of ``algo`` does not take (or that
    ``train`` sets itself), naming the closest allowed key and all of them, or for a value that
    is of the wrong type or out of range; the message names the key, the value, what is allowed
    and where the value came from (``provenance`` as :func:`resolve` gives it). Imports SB3,
    builds nothing."""
    check_algo(algo)
    if not isinstance(kwargs, Mapping):
        raise TrainInputError(f"--algo-kwargs must be a JSON object, got {kwargs!r}")
    name = algo_class(algo).__name__
    allowed = allowed_keys(algo)
    checks = CHECKS[algo]
    for key, value in kwargs.items():
        where = _where(provenance, key)
        if key in RUNNER_KEYS:
            raise TrainInputError(f"{where}: {key!r} is set by train itself "
                                  f"({RUNNER_KEYS[key]})")
        if key not in allowed:
            others = [algo_class(a).__name__ for a in _installed(ALGOS)
                      if a != algo and key in allowed_keys(a)]
            note = f" (an argument of {', '.join(others)}, not of {name})" if others else ""
            raise _unknown(key, allowed, f"{name} argument", where, note)
        problem = checks.get(key, lambda v: None)(value)
        if problem:
            raise TrainInputError(f"{where}: {key}={value!r} not allowed for {name}; "
                                  f"allowed: {problem}")
    policy = kwargs.get("policy_kwargs") or {}
    allowed_policy = allowed_policy_keys(algo)
    pchecks = _policy_checks(algo)
    for key, value in policy.items():
        where = _where(provenance, f"policy_kwargs.{key}")
        if key not in allowed_policy:
            others = [algo_class(a).__name__ for a in _installed(ALGOS)
                      if a != algo and key in allowed_policy_keys(a)]
            note = (f" (a policy_kwargs key of {', '.join(others)}, not of {name})" if others
                    else "")
            raise _unknown(key, allowed_policy, f"{name} policy_kwargs key", where, note)
        problem = pchecks.get(key, lambda v: None)(value)
        if problem:
            raise TrainInputError(f"{where}: policy_kwargs {key}={value!r} not allowed for "
                                  f"{name}; allowed: {problem}")
    if policy.get("shared_lstm") and policy.get("enable_critic_lstm", True):
        where = _where(provenance, "policy_kwargs.shared_lstm")
        raise TrainInputError(f"{where}: policy_kwargs shared_lstm=True with enable_critic_lstm="
                              f"{policy.get('enable_critic_lstm', True)!r} not allowed for "
                              f"{name}; allowed: the critic shares the actor's LSTM "
                              "(shared_lstm=true, enable_critic_lstm=false), has its own "
                              "(enable_critic_lstm=true, the default) or none (both false)")


def _installed(algos) -> list[str]:
    """The algorithms whose classes import here (sb3-contrib may be missing)."""
    out = []
    for a in algos:
        try:
            algo_class(a)
        except TrainInputError:
            continue
        out.append(a)
    return out


# ---------------------------------------------------------------- conversions

def to_sb3(algo: str, kwargs: Mapping[str, Any]) -> dict:
    """SB3 objects for TOML/JSON values: ``"lin_<start>"`` -> :class:`LinearSchedule` (schedule
    keys), activation and optimizer names -> torch classes, ``train_freq`` lists -> tuples.
    Other values are passed as they are (a fresh dict; imports torch)."""
    import torch

    out = dict(kwargs)
    for key in SCHEDULES[check_algo(algo)]:
        start = _lin_start(out.get(key))
        if start is not None:
            out[key] = LinearSchedule(start)
    if isinstance(out.get("train_freq"), list):
        out["train_freq"] = tuple(out["train_freq"])
    if isinstance(out.get("policy_kwargs"), Mapping):
        pk = dict(out["policy_kwargs"])
        if isinstance(pk.get("activation_fn"), str):
            pk["activation_fn"] = getattr(torch.nn, ACTIVATIONS[pk["activation_fn"]])
        if isinstance(pk.get("optimizer_class"), str):
            pk["optimizer_class"] = getattr(torch.optim, OPTIMIZERS[pk["optimizer_class"]])
        out["policy_kwargs"] = pk
    return out


def _class_name(cls) -> str:
    for names, module in ((ACTIVATIONS, "torch.nn"), (OPTIMIZERS, "torch.optim")):
        for short, attr in names.items():
            if cls.__name__ == attr and cls.__module__.startswith(module):
                return short
    return f"{cls.__module__}.{cls.__qualname__}"


def to_json(value):
    """A JSON-serialisable copy for ``config.json``: torch activation and optimizer classes by
    their names (``"tanh"``), other classes by dotted name, :class:`LinearSchedule` as
    ``"lin_<start>"``, tuples as lists, numpy scalars as numbers, other objects by ``repr``."""
    if isinstance(value, Mapping):
        return {str(k): to_json(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_json(v) for v in value]
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if inspect.isclass(value):
        return _class_name(value)
    if isinstance(value, LinearSchedule):
        return repr(value)
    if hasattr(value, "item") and callable(value.item):  # numpy / torch scalars
        return value.item()
    return repr(value)


# ---------------------------------------------------------------- provenance and docs

_KEY_LINE = re.compile(r"^\s*([A-Za-z_][\w-]*)\s*=\s*(.*?)\s*(?:#\s*(.*))?$")
_HEADER = re.compile(r"^\s*\[([^\]]+)\]\s*(?:#.*)?$")


def notes(name: str) -> tuple[str, dict[tuple[str, str], str]]:
    """What a file says about itself: its opening comment (the first paragraph) and each key's
    provenance comment, ``{(table, key): comment}`` (the comment on the key's line, after
    the comment lines directly above it). Values must be one line each (ours are)."""
    lines = (DIRECTORY / name).read_text().splitlines()
    intro, i = [], 0
    while i < len(lines) and lines[i].startswith("#"):
        intro.append(lines[i].lstrip("#").strip())
        i += 1
    out, table, above = {}, "", []
    for line in lines[i:]:
        if line.strip().startswith("#"):
            above.append(line.strip().lstrip("#").strip())
            continue
        header = _HEADER.match(line)
        if header:
            table, above = header.group(1).strip(), []
            continue
        key = _KEY_LINE.match(line)
        if key and "=" in line:
            out[(table, key.group(1))] = " ".join([*above, key.group(3) or ""]).strip()
        above = []
    return " ".join(intro).strip(), out


def _fmt(value) -> str:
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_fmt(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(_fmt(v) for v in value) + "]"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        return f'"{value}"'
    return repr(value) if isinstance(value, float) else str(value)


def _rows(table: str, values: Mapping[str, Any], comments: Mapping) -> list[tuple]:
    rows = []
    for key, value in values.items():
        if isinstance(value, dict) and key in MODES:
            rows += _rows(f"{table}.{key}", value, comments)
        elif isinstance(value, dict) and key == "policy_kwargs":
            rows += [(f"policy_kwargs.{k}", v, comments.get((f"{table}.{key}", k), ""))
                     for k, v in value.items()]
        else:
            rows.append((key, value, comments.get((table, key), "")))
    return rows


def markdown_table() -> str:
    """The shipped values as Markdown: ``default.toml`` (key, one column per algorithm,
    provenance), then every
    task file's changes and what was measured. Regenerate docs/hyperparameters.md's tables with
    ``python -c "from mimo_social.train.hyperparams import markdown_table as m; print(m())"``."""
    intro, comments = notes("default.toml")
    data = _file("default.toml")
    lines = [f"| key | {' | '.join(TITLES[a] for a in ALGOS)} | provenance |",
             "|---" * (len(ALGOS) + 2) + "|"]
    cells: dict[str, dict] = {}
    for algo in ALGOS:
        for key, value, note in _rows(algo, data.get(algo, {}), comments):
            cells.setdefault(key, {})[algo] = (value, note)
    for key, per in cells.items():
        vals = [f"`{_fmt(per[a][0])}`" if a in per else "-" for a in ALGOS]
        prov = "; ".join(dict.fromkeys(per[a][1] for a in ALGOS if a in per))
        lines.append(f"| `{key}` | {' | '.join(vals)} | {prov} |")
    lines += ["", "| task | changes from default.toml | provenance |", "|---|---|---|"]
    for name in shipped_files():
        if name == "default.toml":
            continue
        intro, comments = notes(name)
        data = _file(name)
        changes = [f"`{table}` `{key}` = `{_fmt(v)}`" + (f" ({note})" if note else "")
                   for table in _TABLES for key, v, note in _rows(table, data.get(table, {}),
                                                                  comments)]
        lines.append(f"| `{name[:-5]}` | {'<br>'.join(changes) or 'none'} | {intro} |")
    return "\n".join(lines)
