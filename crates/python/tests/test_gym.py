"""The inspection station and the view-planning environment: Gymnasium's own checks, one seed
one episode, coverage that only grows, the baselines, and bad arguments."""

import math
import subprocess
import sys
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import motorfactory as mf
import motorfactory.gym as mg

FAST = {"sensor.sampling": "blueSubsample4x4"}


def test_the_environment_passes_gymnasiums_checks():
    for view_set in (None, 16):
        env = gym.make(
            "motorfactory/ViewPlanning-v0",
            view_set=view_set,
            num_points=512,
            normals=True,
            render_mode="rgb_array",
        )
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # gymnasium's warnings too
            check_env(env.unwrapped, skip_render_check=False)
        env.reset(seed=1)
        env.step(env.action_space.sample())
        image = env.render()
        assert image.shape == (240, 320, 3) and image.dtype == np.uint8 and image.max() > 24


def test_gymnasium_alone_makes_the_environment_by_its_module_qualified_id():
    # a fresh interpreter that imports nothing of motorfactory: Gymnasium imports the module
    # the id names, which registers the environment (Gymnasium 1.x has no plugin entry points)
    code = (
        "import sys, gymnasium as gym\n"
        "env = gym.make('motorfactory.gym:motorfactory/ViewPlanning-v0', num_points=64)\n"
        "env.reset(seed=0)\n"
        "print(type(env.unwrapped).__name__, 'motorfactory.gym' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["ViewPlanningEnv", "True"]


def test_an_episode_on_a_kept_station_is_that_of_a_new_one():
    def run(env, index):
        obs, info = env.reset(seed=5, options={"index": index, "clamping": "pole-pot-up"})
        out = [(obs["points"].copy(), info["coverage"])]
        for action in (3, 11):
            obs, reward, *_, info = env.step(action)
            out.append((obs["points"].copy(), reward, info["coverage"]))
        return out

    kept = gym.make("motorfactory/ViewPlanning-v0", view_set=16, num_points=256).unwrapped
    first = run(kept, 7)
    station = kept.station
    run(kept, 8)  # another motor between
    again = run(kept, 7)
    assert kept.station is station  # restarted, not made again
    fresh = run(gym.make("motorfactory/ViewPlanning-v0", view_set=16, num_points=256).unwrapped, 7)
    for a, b, c in zip(first, again, fresh):
        for x, y, z in zip(a, b, c):
            np.testing.assert_array_equal(x, y)
            np.testing.assert_array_equal(x, z)


def episode(env, seed, steps=3):
    obs, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    out = [(obs, info["index"], info["clamping"])]
    for _ in range(steps):
        obs, reward, _, _, info = env.step(env.action_space.sample())
        out.append((obs, reward, info["coverage"]))
    return out


def test_one_seed_gives_one_episode():
    env = mg.ViewPlanningEnv(num_points=256)
    a, b = episode(env, 7), episode(env, 7)
    c = episode(env, 8, steps=0)
    assert a[0][1:] == b[0][1:] and a[0][1] != c[0][1]
    for x, y in zip(a, b):
        for k in x[0]:
            np.testing.assert_array_equal(x[0][k], y[0][k])
        assert x[1:] == y[1:]


def test_coverage_only_grows_and_the_reward_is_the_gain_less_the_costs():
    env = mg.ViewPlanningEnv(
        num_points=1024,
        view_set=12,
        view_cost=0.02,
        travel_cost=0.1,
        max_views=4,
        target_coverage=1.0,
    )
    obs, info = env.reset(seed=3, options={"index": 3, "clamping": "pole-pot-up"})
    assert info["index"] == 3 and info["clamping"] == "pole-pot-up" and info["coverage"] == 0.0
    assert not obs["points"].any() and obs["coverage"][0] == 0.0
    last, done = 0.0, False
    for k in range(4):
        assert not done
        obs, reward, terminated, truncated, info = env.step(k * 3)
        assert info["coverage"] >= last and all(
            0.0 <= c <= 1.0 for c in info["coverage_per_part"].values()
        )
        assert math.isclose(info["coverage"] - last, info["gain"], abs_tol=1e-6)
        assert math.isclose(reward, info["gain"] - 0.02 - 0.1 * info["travel"], abs_tol=1e-6)
        # the observation: points of every view so far, this view's marked new
        if k == 0:
            assert obs["new"].all()
        else:
            assert 0 < obs["new"].mean() < 1
        assert np.abs(obs["points"]).max() <= mg.EXTENT
        last, done = info["coverage"], terminated or truncated
    assert truncated and info["views"] == 4


def test_a_view_taken_twice_adds_little_and_the_surface_is_the_stations():
    station = mf.Station("default", 2, "gear-container-up", FAST)
    first = station.capture(0.3, 1.2, 0.6)
    again = station.capture(0.3, 1.2, 0.6)
    assert first["gain"] > 0.05 and again["gain"] < 0.005
    assert first["xyz"].shape == first["normal"].shape and len(first["xyz"]) > 1000
    assert (first["label"] > 0).mean() > 0.3  # the motor's points labelled, the jaws' 0
    surface = station.surface()
    total, parts = station.coverage()
    assert math.isclose(surface["seen"].mean(), total, rel_tol=1e-6)
    assert set(surface["part"]) >= {name for name, _ in parts}
    assert "magnet" not in surface["part"]
    pose = np.array(station.camera_pose(0.3, 1.2, 0.6))
    assert np.allclose(np.linalg.norm(pose[:3, 3] - station.centre), 0.6, atol=1e-5)


def mean_curve(policy, motors=3, views=5):
    env = mg.ViewPlanningEnv(view_set=24, max_views=views, target_coverage=1.0, num_points=64)
    curves = []
    for m in range(motors):
        env.reset(seed=m, options={"index": m, "clamping": mg.CLAMPINGS[m % 2]})
        env.action_space.seed(m)
        curve = []
        for _ in range(views):
            _, _, _, _, info = env.step(policy(env))
            curve.append(info["coverage"])
        curves.append(curve)
    return np.mean(curves, axis=0)


def test_the_greedy_next_best_view_beats_random_views():
    greedy, random = mean_curve(mg.greedy_view), mean_curve(mg.random_view)
    print("greedy", greedy.round(3), "random", random.round(3))
    assert (greedy >= random - 0.02).all() and greedy[2] > random[2] + 0.05


def test_bad_arguments_are_refused_with_the_value():
    with pytest.raises(ValueError, match="distance = \\(0.01, 0.7\\) is not allowed"):
        mg.ViewPlanningEnv(distance=(0.01, 0.7))
    with pytest.raises(ValueError, match='clamping = "upside-down" is not allowed'):
        mf.Station("default", 0, "upside-down")
    with pytest.raises(ValueError, match="distance = 5 m is not allowed"):
        mf.Station("default", 0, overrides=FAST, density=1e3).capture(0.0, 1.0, 5.0)
    with pytest.raises(ValueError, match="greedy_view needs a discrete view set"):
        env = mg.ViewPlanningEnv()
        env.reset(seed=0)
        mg.greedy_view(env)
