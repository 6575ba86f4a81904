"""What the agents are asked to do: one folder per task, ``tasks/<task>/`` (``task.py``: the Task
subclass, its options dataclass and its env factories; ``controller.py``: its scripted solution;
``measures.py``: a paradigm's measures; ``__init__.py``: its table, the one source of its part
of docs/tasks.md), and the helpers several tasks share (``common``, ``dyad``). No task imports
another task's folder."""
