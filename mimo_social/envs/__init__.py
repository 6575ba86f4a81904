"""The shelf users import: one `<task>_v0` module per env (`parallel_env`, `env`, and
`scripted_env` for social tasks) and :mod:`.catalog`, the one list of envs."""
