"""Vocal turn-taking (being assembled: the scheduling, the measures and the infant rule)."""
