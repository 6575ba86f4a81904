"""``SB3InitPPOModule``: RLlib's default PPO RLModule (torch) with Stable-Baselines3's weights at
the start, the module :func:`~mimo_social.train.rllib.config.build_config` gives PPO.

SB3's ``ActorCriticPolicy`` starts with orthogonal weights and zero biases: gain sqrt(2) in the
hidden layers, 0.01 on the action-mean layer (so the first mean actions are ~0) and 1 on the
value layer. RLlib 2.60's PPO catalog builds its policy and value heads with torch's default
(uniform) initialisation whatever ``head_fcnet_kernel_initializer`` says, so the initial mean
actions are ~25 times larger than SB3's (0.12 vs 0.005 in mean |action| on high five). This
module re-initialises every linear layer the SB3 way after RLlib built it; the model config
(``free_log_std``: a state-free log std starting at 0, separate policy and value networks) is
left to the config. Imports ray: load it only where ray is installed.
"""

from __future__ import annotations

import math

import torch
from ray.rllib.algorithms.ppo.torch.default_ppo_torch_rl_module import DefaultPPOTorchRLModule

__all__ = ["SB3InitPPOModule", "sb3_init_"]

HIDDEN_GAIN = math.sqrt(2.0)
PI_GAIN = 0.01
VF_GAIN = 1.0


def _linears(net: torch.nn.Module) -> list[torch.nn.Linear]:
    return [m for m in net.modules() if isinstance(m, torch.nn.Linear)]


def sb3_init_(module: torch.nn.Module) -> None:
    """In place: every linear layer of ``module`` orthogonal (gain sqrt 2, bias 0), then the
    last one of its ``pi`` head gain 0.01 and the last one of its ``vf`` head (where it has one:
    an inference-only module has none) gain 1."""
    with torch.no_grad():
        for lin in _linears(module):
            torch.nn.init.orthogonal_(lin.weight, gain=HIDDEN_GAIN)
            torch.nn.init.zeros_(lin.bias)
        for name, gain in (("pi", PI_GAIN), ("vf", VF_GAIN)):
            head = getattr(module, name, None)
            layers = _linears(head) if head is not None else []
            if layers:
                torch.nn.init.orthogonal_(layers[-1].weight, gain=gain)


class SB3InitPPOModule(DefaultPPOTorchRLModule):
    """RLlib's default PPO module, its weights initialised as SB3's (module docstring)."""

    def setup(self):
        super().setup()
        sb3_init_(self)
