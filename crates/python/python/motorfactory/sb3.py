"""Stable-Baselines3 on the view-planning environment (``stable-baselines3`` needed).

:class:`PointNetExtractor` is a features extractor for :class:`motorfactory.gym.ViewPlanningEnv`'s
cloud observation: the points (with their ``new`` flag, and their normals when observed) through
a :class:`motorfactory.nn.PointNet`, every other entry (the coverage, the views taken) flattened
beside its features. Stable-Baselines3's own extractor flattens the cloud, whose points are drawn
anew every step, so that no entry means the same twice and nothing can be learned.

    from stable_baselines3 import PPO
    from motorfactory.sb3 import PointNetExtractor
    env = gym.make("motorfactory.gym:motorfactory/ViewPlanning-v0", view_set=32, num_points=1024)
    model = PPO("MultiInputPolicy", env,
                policy_kwargs={"features_extractor_class": PointNetExtractor})

With ``observation="vector"`` the environment needs no extractor of its own:
``PPO("MultiInputPolicy", env)`` (or SB3-contrib's ``MaskablePPO``, which reads the
environment's ``action_masks``).
"""

from __future__ import annotations

import torch
from gymnasium import spaces
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor

from .nn import PointNet

# the cloud's entries; every other entry of the observation is flattened beside its features
CLOUD = ("points", "new", "normals")


class PointNetExtractor(BaseFeaturesExtractor):
    """Features of a cloud observation (``points``, ``new``, ``normals``) by a PointNet, the
    other entries flattened beside them.

    Parameters:
        observation_space: the environment's (a ``Dict`` with ``points``).
        features: the PointNet's output length.
        scale: the points' positions are multiplied by it (m; 10 takes a motor's +-0.1 m to
            +-1, where a perceptron's weights start).
    """

    def __init__(self, observation_space: spaces.Dict, features: int = 128, scale: float = 10.0):
        if not isinstance(observation_space, spaces.Dict) or "points" not in observation_space.spaces:
            raise ValueError(
                "PointNetExtractor needs a cloud observation: a Dict with 'points' "
                '(ViewPlanningEnv with observation="cloud")'
            )
        self.others = [k for k in observation_space.spaces if k not in CLOUD]
        flat = sum(spaces.flatdim(observation_space[k]) for k in self.others)
        super().__init__(observation_space, features + flat)
        self.normals = "normals" in observation_space.spaces
        self.has_new = "new" in observation_space.spaces
        self.scale = scale
        self.pointnet = PointNet(3 + self.has_new + 3 * self.normals, features)

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        cloud = [observations["points"] * self.scale]
        if self.has_new:
            cloud.append(observations["new"].unsqueeze(-1))
        if self.normals:
            cloud.append(observations["normals"])
        features = self.pointnet(torch.cat(cloud, dim=-1))
        return torch.cat([features] + [observations[k].flatten(1) for k in self.others], dim=1)
