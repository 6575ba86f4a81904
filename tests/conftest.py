import mimo_social  # noqa: F401  (chooses the headless GL backend before mujoco is imported)
