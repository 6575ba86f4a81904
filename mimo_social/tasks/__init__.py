"""What the agents are asked to do: one module per task (a Task subclass, its options dataclass
and its docstring table, the one source of docs/tasks.md) and helpers shared by tasks."""
