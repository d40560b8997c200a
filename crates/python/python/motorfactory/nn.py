"""Networks for motorfactory's clouds (``torch`` needed).

:class:`PointNet` turns a cloud of any number of points, in any order, into one feature vector:
the shared per-point perceptron and max pooling of PointNet (Qi et al., CVPR 2017), without its
input and feature transforms or batch normalisation (which reinforcement learning's small,
correlated batches upset). :mod:`motorfactory.sb3` wraps it for Stable-Baselines3.

    from motorfactory.nn import PointNet
    net = PointNet(channels=3, features=128)
    features = net(points)  # (batch, points, 3) -> (batch, 128)
"""

from __future__ import annotations

from collections.abc import Sequence

import torch
from torch import nn


class PointNet(nn.Module):
    """A cloud (batch, points, channels) to a feature vector (batch, features), the same
    whatever the points' order.

    Parameters:
        channels: numbers per point (3 for positions; more for flags, normals, colour).
        features: the output's length.
        hidden: the widths of the per-point perceptron's hidden layers.
    """

    def __init__(self, channels: int = 3, features: int = 128, hidden: Sequence[int] = (64, 128)):
        super().__init__()
        layers: list[nn.Module] = []
        width = channels
        for out in (*hidden, features):
            layers += [nn.Linear(width, out), nn.ReLU()]
            width = out
        self.per_point = nn.Sequential(*layers)
        self.features = features

    def forward(self, points: torch.Tensor) -> torch.Tensor:
        return self.per_point(points).amax(dim=-2)
