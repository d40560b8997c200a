"""The view-planning baselines: coverage after each view, the mean over 20 motors (10 in each
clamping), random views and the greedy next-best view on a 32-view set; with the environment's
step and reset times (medians; a reset on a new motor, and one on the same motor again). Writes
the figures to standard output and the plot to the file given (docs/view-planning.png).

    .venv/bin/pip install ./crates/python gymnasium matplotlib
    .venv/bin/python bench/view_planning.py docs/view-planning.png
"""

import sys
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import motorfactory.gym as mg

MOTORS, VIEWS, VIEW_SET = 20, 10, 32


def run(policy):
    env = mg.ViewPlanningEnv(view_set=VIEW_SET, max_views=VIEWS, target_coverage=1.0)
    curves, steps, resets, again = [], [], [], []
    for m in range(MOTORS):
        options = {"index": m, "clamping": mg.CLAMPINGS[m % 2]}
        # a reset on a new motor, then one on the same motor (its station kept, restarted)
        t = time.perf_counter()
        env.reset(seed=m, options=options)
        resets.append(time.perf_counter() - t)
        t = time.perf_counter()
        env.reset(seed=m, options=options)
        again.append(time.perf_counter() - t)
        env.action_space.seed(m)
        curve = [0.0]
        for _ in range(VIEWS):
            action = policy(env)
            t = time.perf_counter()
            _, _, _, _, info = env.step(action)
            steps.append(time.perf_counter() - t)
            curve.append(info["coverage"])
        curves.append(curve)
    return np.array(curves), np.median(steps), np.median(resets), np.median(again)


def main(out):
    plt.figure(figsize=(6, 4))
    for name, policy in [
        ("greedy next-best view", mg.greedy_view),
        ("random views", mg.random_view),
    ]:
        t = time.perf_counter()
        curves, step, reset, again = run(policy)
        mean, sd = curves.mean(axis=0), curves.std(axis=0)
        print(f"{name}: mean coverage after 0..{VIEWS} views {np.round(mean, 3).tolist()}")
        print(
            f"  per clamping after {VIEWS} views: gear container up "
            f"{curves[0::2, -1].mean():.3f}, pole pot up {curves[1::2, -1].mean():.3f}"
        )
        print(
            f"  step {step * 1e3:.1f} ms, reset {reset * 1e3:.0f} ms on a new motor "
            f"({reset / step:.1f} steps), {again * 1e3:.1f} ms on the same motor again "
            f"({again / step:.2f} steps) (medians); "
            f"{time.perf_counter() - t:.0f} s in all"
        )
        x = np.arange(VIEWS + 1)
        plt.plot(x, mean, marker="o", label=name)
        plt.fill_between(x, mean - sd, mean + sd, alpha=0.2)
    plt.xlabel("views")
    plt.ylabel("surface covered (share)")
    plt.title(f"ViewPlanning-v0, 612x512: mean of {MOTORS} motors, ± 1 sd", fontsize=10)
    plt.ylim(0, 1)
    plt.grid(alpha=0.3)
    plt.legend(loc="lower right")
    plt.tight_layout()
    plt.savefig(out, dpi=110)
    print(f"plot written to {out}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "view-planning.png")
