"""Trains PPO to plan views of unseen motors, on the CPU, and scores it on held-out motors
against random views and the greedy next-best view.

The policy sees the cloud measured so far (points and normals) through motorfactory's PointNet
features extractor (``motorfactory.sb3.PointNetExtractor``), with the views taken; it chooses among 32 views spread
over the viewing sphere, 10 views an episode, and is rewarded for the surface it sees first.
SB3-contrib's ``MaskablePPO`` (PPO that never draws a masked action) reads the environment's
``action_masks``, so no view is taken twice. Training draws a new motor every episode (any of
the ``default`` configuration's variants); the held-out motors are samples 1,000,000 on, which
training draws with odds under 10^-12. The surface is sampled at 5 10^4 per m^2 (a quarter of
the environment's default, a reset the faster), for training and scoring alike.

    pip install stable-baselines3 sb3-contrib matplotlib
    python examples/python/train_view_planning.py --steps 16000 --plot docs/view-planning-ppo.png

Prints the training curve (the coverage of the last training episodes as it goes), then each
policy's mean coverage after 1 to 10 views on the held-out motors. The last line is a JSON
summary for scripts.
"""

import argparse
import json
import time

import numpy as np
from sb3_contrib import MaskablePPO
from stable_baselines3.common.callbacks import BaseCallback

import motorfactory.gym as mg
from motorfactory.sb3 import PointNetExtractor

HELD_OUT = 1_000_000


def make_env(args) -> mg.ViewPlanningEnv:
    # the baselines' task: every episode 10 views, scored by the coverage after them
    return mg.ViewPlanningEnv(
        view_set=args.view_set,
        num_points=args.points,
        normals=True,
        max_views=args.views,
        target_coverage=1.0,
        density=args.density,
    )


class Curve(BaseCallback):
    """Records each training episode's final coverage, and prints the mean of the last ones
    after every rollout."""

    def __init__(self) -> None:
        super().__init__()
        self.episodes: list[tuple[int, float]] = []
        self.started = time.perf_counter()

    def _on_step(self) -> bool:
        for done, info in zip(self.locals["dones"], self.locals["infos"]):
            if done:
                self.episodes.append((self.num_timesteps, info["coverage"]))
        return True

    def _on_rollout_end(self) -> None:
        last = [c for _, c in self.episodes[-50:]]
        if last:
            print(
                f"step {self.num_timesteps:6d}  coverage after {len(last)} last episodes "
                f"{np.mean(last):.3f}  ({time.perf_counter() - self.started:.0f} s)",
                flush=True,
            )


def score(env: mg.ViewPlanningEnv, policy, motors: int) -> np.ndarray:
    """Coverage after each view, one row per held-out motor (both clampings in turn)."""
    curves = []
    for m in range(motors):
        index = HELD_OUT + m
        obs, _ = env.reset(seed=index, options={"index": index, "clamping": mg.CLAMPINGS[m % 2]})
        env.action_space.seed(index)
        curve = []
        for _ in range(env.max_views):
            obs, _, terminated, truncated, info = env.step(policy(env, obs))
            curve.append(info["coverage"])
        curves.append(curve)
    return np.array(curves)


def random_unseen(env: mg.ViewPlanningEnv) -> int:
    """A view drawn uniformly from those not taken yet."""
    free = np.flatnonzero(env.action_masks())
    return int(free[env.action_space.np_random.integers(len(free))])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--steps", type=int, default=16000, help="training steps (views)")
    p.add_argument("--points", type=int, default=256, help="points in the observed cloud")
    p.add_argument("--density", type=float, default=5e4, help="surface samples per m^2")
    p.add_argument("--view-set", type=int, default=32)
    p.add_argument("--views", type=int, default=10, help="views an episode")
    p.add_argument("--motors", type=int, default=20, help="held-out motors scored")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--plot", help="write the training curve and the scores to this PNG")
    args = p.parse_args()

    env = make_env(args)
    env.reset(seed=args.seed)
    model = MaskablePPO(
        "MultiInputPolicy",
        env,
        policy_kwargs={"features_extractor_class": PointNetExtractor},
        n_steps=250,
        batch_size=50,
        n_epochs=5,
        gamma=0.95,
        learning_rate=1e-3,
        seed=args.seed,
        device="cpu",
    )
    curve = Curve()
    started = time.perf_counter()
    model.learn(args.steps, callback=curve)
    trained = time.perf_counter() - started

    def ppo(env, obs):
        return int(model.predict(obs, deterministic=True, action_masks=env.action_masks())[0])

    policies = {
        "PPO, PointNet extractor": ppo,
        "random views": lambda env, obs: mg.random_view(env),
        "random views not taken before": lambda env, obs: random_unseen(env),
        "greedy next-best view": lambda env, obs: mg.greedy_view(env),
    }
    held_out = make_env(args)
    scores = {name: score(held_out, policy, args.motors) for name, policy in policies.items()}
    print(f"held-out motors {HELD_OUT} to {HELD_OUT + args.motors - 1}, mean coverage after 1 to "
          f"{args.views} views:")
    for name, s in scores.items():
        print(f"  {name:32s} {np.round(s.mean(axis=0), 3).tolist()}")
    if args.plot:
        plot(args, curve.episodes, scores)
    print(
        json.dumps(
            {
                "steps": args.steps,
                "training_seconds": round(trained),
                "episodes": len(curve.episodes),
                "held_out_motors": args.motors,
                "coverage_after_views": {
                    name: round(float(s[:, -1].mean()), 4) for name, s in scores.items()
                },
            }
        )
    )


def plot(args, episodes, scores) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    steps, covered = np.array(episodes).T
    window = 50
    if len(covered) >= window:
        mean = np.convolve(covered, np.ones(window) / window, mode="valid")
        a.plot(steps[window - 1 :], mean, label=f"PPO training episodes (mean of {window})")
    for name in ("random views", "greedy next-best view"):
        a.axhline(scores[name][:, -1].mean(), ls="--", color="grey" if "random" in name else "k",
                  label=f"{name}, held out")
    a.set_xlabel("training steps (views)")
    a.set_ylabel(f"coverage after {args.views} views")
    a.legend(fontsize=8)
    a.grid(alpha=0.3)
    x = np.arange(1, args.views + 1)
    for name, s in scores.items():
        b.plot(x, s.mean(axis=0), marker="o", label=name)
    b.set_xlabel("views")
    b.set_ylabel("surface covered (share)")
    b.set_title(f"{args.motors} held-out motors", fontsize=10)
    b.set_ylim(0, 1)
    b.grid(alpha=0.3)
    b.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(args.plot, dpi=110)
    print(f"plot written to {args.plot}")


if __name__ == "__main__":
    main()
