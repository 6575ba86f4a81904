"""The interface every actuation model implements (spring-damper, muscles).

One instance drives one agent. The world calls, in this order:
``bind`` once after compiling, ``apply`` once per control step with the agent's validated
controls, ``substep`` before every physics step (activation dynamics live here), and
``observation`` / ``cost`` / ``weighted_cost`` when asked.
"""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np


class Actuation(ABC):
    name: str = ""
    needs_substep: bool = False  # True when `substep` must run before every physics step

    def __init__(self, joints: list, actuator_ids: np.ndarray):
        """``joints``: the JointSpec of each motor, in action order; ``actuator_ids``: MuJoCo ids."""
        self.joints = list(joints)
        self.actuator_ids = np.asarray(actuator_ids, dtype=np.intp)

    @property
    def n_controls(self) -> int:
        return len(self.control_low)

    @property
    def control_names(self) -> list[str]:
        """One label per control value (the motor's joint), for messages and plots."""
        return [j.name for j in self.joints]

    @property
    @abstractmethod
    def control_low(self) -> np.ndarray: ...

    @property
    @abstractmethod
    def control_high(self) -> np.ndarray: ...

    @abstractmethod
    def apply(self, model, data, controls: np.ndarray) -> None:
        """Take the agent's controls for the next control step."""

    def substep(self, model, data) -> None:
        """Called before every physics step (no-op for stateless models)."""

    def reset(self, model, data) -> None:
        """Clear internal state at episode start."""

    def retune(self, joints: list) -> None:
        """The same motors with the parameters of ``joints`` (the JointSpec of each motor, in
        action order: the body at another age); the state is cleared and a model that adapts
        its motors adapts them again at the next reset."""
        if [j.name for j in joints] != [j.name for j in self.joints]:
            raise ValueError("retune: the joints must be those of the motors, in action order")
        type(self).__init__(self, joints, self.actuator_ids)

    @property
    @abstractmethod
    def observation_size(self) -> int: ...

    @abstractmethod
    def observation(self, data) -> np.ndarray:
        """The actuation state, for proprioception."""

    @abstractmethod
    def cost(self, controls: np.ndarray) -> float:
        """The paper's c(u)."""

    @abstractmethod
    def weighted_cost(self, controls: np.ndarray) -> float:
        """The paper's c_w(u): effort weighted by actuator strength."""

    def costs(self, controls: np.ndarray) -> tuple[float, float]:
        """``(cost(controls), weighted_cost(controls))``, what the infos report each step (a
        model overrides it where the two share work)."""
        return self.cost(controls), self.weighted_cost(controls)
