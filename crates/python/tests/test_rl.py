"""Reinforcement learning on the view-planning environment with Stable-Baselines3 and
SB3-contrib from the package registry: the PointNet extractor, the vector observation, the views
taken and their action masks."""

import warnings

import numpy as np
import pytest
import torch
from sb3_contrib import MaskablePPO
from stable_baselines3 import PPO
from stable_baselines3.common.env_checker import check_env

import motorfactory.gym as mg
from motorfactory.nn import PointNet
from motorfactory.sb3 import PointNetExtractor

# a coarse surface: resets the faster
SMALL = {"density": 2e4, "num_points": 128}


def test_ppo_with_the_pointnet_extractor_learns_a_few_hundred_steps_unwrapped():
    env = mg.ViewPlanningEnv(view_set=16, normals=True, **SMALL)
    model = PPO(
        "MultiInputPolicy",
        env,
        policy_kwargs={"features_extractor_class": PointNetExtractor},
        n_steps=100,
        batch_size=50,
        n_epochs=2,
        seed=0,
        device="cpu",
    )
    extractor = model.policy.features_extractor
    assert isinstance(extractor, PointNetExtractor)
    # the PointNet's features, the coverage and the 16 views taken beside them
    assert extractor.features_dim == 128 + 1 + 16
    before = [p.detach().clone() for p in extractor.pointnet.parameters()]
    model.learn(300)
    assert model.num_timesteps >= 300
    assert any(
        not torch.equal(a, b) for a, b in zip(before, extractor.pointnet.parameters())
    )  # the extractor trained
    action, _ = model.predict(env.reset(seed=1)[0], deterministic=True)
    assert env.action_space.contains(int(action))


def test_maskable_ppo_on_the_vector_observation_never_takes_a_view_twice():
    env = mg.ViewPlanningEnv(view_set=12, observation="vector", max_views=8, target_coverage=1.0,
                             density=2e4)
    model = MaskablePPO("MultiInputPolicy", env, n_steps=64, batch_size=32, n_epochs=2, seed=0,
                        device="cpu")
    model.learn(200)
    obs, _ = env.reset(seed=3)
    taken = []
    for _ in range(8):
        mask = env.action_masks()
        assert mask.tolist() == (obs["taken"] == 0).tolist()
        action = int(model.predict(obs, action_masks=mask)[0])
        obs, *_ = env.step(action)
        taken.append(action)
    assert len(set(taken)) == 8 and obs["taken"].sum() == 8


def test_stable_baselines3s_checks_pass():
    for observation in ("cloud", "vector"):
        env = mg.ViewPlanningEnv(view_set=8, observation=observation, **SMALL)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            check_env(env)
        said = [str(w.message) for w in caught]
        if observation == "vector":
            assert said == []
        else:  # SB3's own extractor would flatten the cloud: PointNetExtractor is for it
            assert all("points has an unconventional shape" in s for s in said), said
    env = mg.ViewPlanningEnv(observation="vector", **SMALL)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env)
    assert [str(w.message) for w in caught] == []


def test_the_vector_observation_means_the_same_in_every_episode():
    env = mg.ViewPlanningEnv(view_set=16, observation="vector", target_coverage=1.0, density=2e4)
    obs, _ = env.reset(seed=2, options={"index": 2, "clamping": "pole-pot-up"})
    assert obs["occupancy"].sum() == 0 and obs["coverage_by_direction"].sum() == 0
    for k, action in enumerate((0, 5, 11)):
        obs, _, _, _, info = env.step(action)
        assert env.observation_space.contains(obs)
        # the coverage by direction, weighted by the surface facing each, is the coverage
        count = env._facing_count
        total = (obs["coverage_by_direction"] * count).sum() / count.sum()
        assert total == pytest.approx(info["coverage"], abs=1e-5)
        # the occupied cells are those of the cloud's points inside the grid
        cell = np.floor((env.cloud + mg.GRID_EXTENT) * mg.GRID / (2 * mg.GRID_EXTENT))
        cell = cell[((cell >= 0) & (cell < mg.GRID)).all(axis=1)].astype(int)
        occupied = np.zeros(mg.GRID**3, np.int8)
        occupied[cell[:, 0] + mg.GRID * (cell[:, 1] + mg.GRID * cell[:, 2])] = 1
        np.testing.assert_array_equal(obs["occupancy"], occupied)
        assert 0 < occupied.sum() < mg.GRID**3
        assert obs["views"][0] == pytest.approx((k + 1) / env.max_views)
    assert np.flatnonzero(obs["taken"]).tolist() == [0, 5, 11]
    assert np.flatnonzero(~env.action_masks()).tolist() == [0, 5, 11]
    # each facing's samples face it more than any other direction
    normals = env.station.surface()["normal"]
    np.testing.assert_array_equal(env._facing, np.argmax(normals @ env.facings.T, axis=1))

    continuous = mg.ViewPlanningEnv(observation="vector", max_views=4, density=2e4)
    obs, _ = continuous.reset(seed=2)
    action = np.array([0.5, -0.2, 0.1, 0.0], np.float32)
    obs, *_ = continuous.step(action)
    np.testing.assert_array_equal(obs["poses"][:4], action)
    assert obs["poses"].shape == (16,) and not obs["poses"][4:].any()
    with pytest.raises(ValueError, match="action masks need a discrete view set"):
        continuous.action_masks()


def test_the_cloud_observation_says_which_views_were_taken():
    env = mg.ViewPlanningEnv(view_set=8, **SMALL)
    obs, _ = env.reset(seed=0)
    assert obs["taken"].tolist() == [0] * 8
    obs, *_ = env.step(3)
    assert obs["taken"].tolist() == [0, 0, 0, 1, 0, 0, 0, 0]
    assert "taken" not in mg.ViewPlanningEnv(**SMALL).observation_space.spaces


def test_the_default_target_is_one_the_greedy_view_reaches():
    env = mg.ViewPlanningEnv(view_set=32, num_points=64)
    ends = []
    for m in range(4):
        env.reset(seed=m, options={"index": m, "clamping": mg.CLAMPINGS[m % 2]})
        for _ in range(env.max_views):
            _, _, terminated, truncated, info = env.step(mg.greedy_view(env))
            if terminated or truncated:
                break
        ends.append((terminated, info["views"]))
    assert all(terminated for terminated, _ in ends), ends
    assert all(views < env.max_views for _, views in ends), ends


def test_the_pointnet_ignores_the_points_order():
    torch.manual_seed(0)
    net = PointNet(channels=4, features=32)
    cloud = torch.randn(2, 100, 4)
    shuffled = cloud[:, torch.randperm(100)]
    assert net(cloud).shape == (2, 32)
    torch.testing.assert_close(net(cloud), net(shuffled))
    with pytest.raises(ValueError, match="PointNetExtractor needs a cloud observation"):
        PointNetExtractor(mg.ViewPlanningEnv(observation="vector", **SMALL).observation_space)
