"""The simulation core: agent and physics config, the World (N bodies and a scene in one
MuJoCo model), the Task hooks, kinematics, the PettingZoo ParallelEnv, the Gymnasium adapter,
generic wrappers and smooth random actions. See docs/architecture.md."""
