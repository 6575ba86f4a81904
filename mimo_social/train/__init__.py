"""Train, evaluate and compare policies (``mimo-social train | eval | compare``).

One-agent tasks (:data:`TASKS`: reach, standup, selfbody, catch) and the multi-agent social tasks
(:data:`MULTI_TASKS`: high_five, mirror, joint_attention, social_touch, handover), both read from
the catalogue (:mod:`mimo_social.envs.catalog`). A social task learns in one of three modes
(details and limits in docs/training_multi.md):

* ``shared`` (default): parameter sharing, one policy for every agent through SuperSuit
  (:func:`~mimo_social.train.vector.sb3_vec_env`; one VecEnv slot per agent, ``n_envs`` worlds,
  ``n_cpus`` worker processes); every agent needs the same observation and action space;
* ``independent``: one policy per agent, all acting in the same worlds at the same time (each
  model's ``learn()`` in its own thread on a lockstep VecEnv of its slots in ``n_envs`` worlds,
  ``n_cpus`` worker processes; :mod:`mimo_social.train.independent`);
* ``scripted``: one learner, its partner driven by the task's default scripted partner: the
  catalogue's Gymnasium id of the task, the same path as a one-agent task.

The modules, each one concern (each imports only those above it in this list):

``tasks``       which tasks, algorithms and modes exist; :class:`TrainInputError`
``envs``        the envs SB3 learns on (:func:`make_env`, :func:`make_sb3_single`, flat ParallelEnvs)
``progress``    ``progress.csv`` and ``config.json``
``plots``       learning curves and compare plots
``rollouts``    episodes with trained policies and their numbers
``runlog``      the multi-agent modes' run log and schedule
``lockstep``    one ParallelEnv stepped by one learner thread per agent
``single``      one learner; ``independent`` / ``multi``: the multi-agent modes
``runner``      :func:`train`, the entry point; ``evaluation``: :func:`evaluate`;
``comparison``  :func:`compare`; ``recipes``: the shipped per-task recipes and their check;
``fig8``        the paper's Fig. 8 (PPO and SAC on its four tasks, several seeds) in one call
``vector``      SB3 vector envs with parameter sharing (imports SB3; not imported here)
``obs_norm``    ``RunningNorm``, input normalisation inside the policy (imports torch)

``--steps`` counts environment steps in every mode. Importing this package imports neither SB3
nor torch (a spawned vector env worker imports :mod:`mimo_social.train.envs`).
"""

from .comparison import compare
from .envs import make_env, make_parallel_env, make_sb3_single, make_scripted_env
from .evaluation import EvalOutputs, VideoUnavailable, evaluate
from .lockstep import AgentView, Lockstep, LockstepAborted, LockstepError, run_lockstep
from .plots import plot_compare, plot_learning_curve
from .progress import PROGRESS_FIELDS, agent_columns, progress_agents, read_progress, write_progress
from .rollouts import evaluate_agents, run_episode
from .runner import train
from .tasks import (ALGOS, ALL_TASKS, DEFAULT_MODE, MODES, MULTI_TASKS, TASKS, TrainInputError,
                    check_mode, task_module)

__all__ = ["train", "evaluate", "compare", "plot_learning_curve", "plot_compare",
           "read_progress", "write_progress", "progress_agents", "agent_columns",
           "PROGRESS_FIELDS", "TASKS", "MULTI_TASKS", "ALL_TASKS", "ALGOS", "MODES",
           "DEFAULT_MODE", "TrainInputError", "VideoUnavailable", "EvalOutputs", "check_mode",
           "task_module", "make_env", "make_sb3_single", "make_parallel_env", "make_scripted_env",
           "evaluate_agents", "run_episode", "Lockstep", "AgentView", "LockstepError",
           "LockstepAborted", "run_lockstep"]
