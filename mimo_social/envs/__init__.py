"""Environments: the world, the PettingZoo ParallelEnv, the Gymnasium adapter and the tasks."""
