"""View planning at the inspection station as a Gymnasium environment (``gymnasium`` needed).

``ViewPlanningEnv``, registered as ``motorfactory/ViewPlanning-v0`` when this module is
imported (``gym.make("motorfactory.gym:motorfactory/ViewPlanning-v0")`` imports it; Gymnasium
1.x loads no plugins, so the bare id needs ``import motorfactory.gym`` first): each episode clamps an
unseen motor (any variant of the configuration's parameter space) in one of the station's two
setups; each step places the structured-light camera on a viewing sphere round the motor, scans
the cell and rewards the surface seen for the first time, less a cost per view (and per radian
travelled). The observation is the cloud measured so far, a fixed number of points, for a
point-cloud network (:mod:`motorfactory.nn`, :mod:`motorfactory.sb3`); or, with
``observation="vector"``, fixed-length vectors whose every entry means the same in every episode,
for a multilayer perceptron. With a discrete view set it says which views were taken, and
:meth:`ViewPlanningEnv.action_masks` masks them (SB3-contrib's ``MaskablePPO`` convention).

Two baselines: :func:`random_view` and :func:`greedy_view` (next-best view: the candidate an
ideal sensor would see the most new surface from; it knows the motor's surface, so it bounds
what a policy learns from the clouds alone).

    import gymnasium as gym
    env = gym.make("motorfactory.gym:motorfactory/ViewPlanning-v0", view_set=32)
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

import gymnasium
import numpy as np
from gymnasium import spaces

from ._core import Station

CLAMPINGS = ("gear-container-up", "pole-pot-up")

# views at the default 612 x 512 (the Zivid 2+ M60 sampling the blue pixels of each 4 x 4 block)
DEFAULT_OVERRIDES = {"sensor.sampling": "blueSubsample4x4"}

# half the side of the cube the observed points lie in, about the motor's centre, m
EXTENT = 0.5

# stations (a motor clamped, its surface sampled, the cell's world) an environment keeps for
# episodes on the same motor and clamping again
STATIONS_KEPT = 4

OBSERVATIONS = ("cloud", "vector")

# the vector observation: the surface's coverage by the direction it faces (this many directions
# over the whole sphere), and the cloud's occupancy of a grid of GRID^3 cells, GRID_EXTENT (m)
# either side of the motor's centre (a motor's points lie within 0.11 m of it)
FACINGS = 32
GRID = 8
GRID_EXTENT = 0.12


def sphere_views(count: int, min_elevation: float, distance: float) -> np.ndarray:
    """``count`` views (azimuth, elevation, distance, roll) spread evenly over the viewing
    sphere's cap above ``min_elevation`` (radians, -pi/2 for the whole sphere), a spiral of
    equal areas."""
    k = np.arange(count) + 0.5
    top, bottom = 1.0, math.sin(min_elevation)
    elevation = np.arcsin(top - (top - bottom) * k / count)
    azimuth = np.remainder(k * math.pi * (3.0 - math.sqrt(5.0)) + math.pi, 2 * math.pi) - math.pi
    return np.stack([azimuth, elevation, np.full(count, distance), np.zeros(count)], axis=1).astype(
        np.float32
    )


class ViewPlanningEnv(gymnasium.Env):
    """Place the camera so that the whole surface of an unseen motor is covered.

    Parameters:
        config, overrides: the dataset configuration whose motors, cell and sensor are used (as
            for ``motorfactory.Generator``); by default ``default`` at 612 x 512.
        observation: ``"cloud"``: ``points`` (the cloud so far, ``num_points`` drawn from it,
            centred on the motor, m), ``new`` (1 where a point is the latest view's), the
            ``coverage`` so far, with ``normals=True`` the points' normals, and in a view set
            ``taken`` (1 for each view taken). ``"vector"``: ``coverage``,
            ``coverage_by_direction`` (the share covered of the surface facing each of
            ``FACINGS`` directions spread over the sphere from the top down), ``occupancy`` (1 for
            each cell of a ``GRID``-cubed grid round the motor holding a measured point, x
            fastest), ``views`` (views taken over ``max_views``), and ``taken`` in a view set or
            ``poses`` (the actions so far, one after the other, zeros after) otherwise.
        num_points: points in the observation's cloud.
        normals: also observe the points' normals.
        view_set: ``None`` for continuous actions, four numbers from -1 to 1 spanning the
            azimuth (-pi to pi), elevation (``min_elevation`` to pi/2), distance and roll (-pi to
            pi); a count for a discrete choice among that many views spread over the sphere.
        target_coverage: the episode ends when this share of the surface is covered. The
            default, 0.6, is one a good policy reaches: the greedy next-best view of 32 reaches
            it within 10 views on every motor standing and 95 % of those lying (median 3 and 6
            views), where 0.65 is reached on 15 % of those lying (40 motors).
        max_views: the episode is cut off after this many views.
        view_cost: subtracted from each step's reward.
        travel_cost: subtracted per radian between the previous view's direction and this one's.
        min_elevation: lowest camera elevation above the horizontal, radians.
        distance: the camera's distance range from the motor's centre, m (within the sensor's
            working range); the view set's views lie at its middle.
        clampings: the setups an episode draws from.
        density, radius, max_angle: the coverage's surface sampling and rule (see ``Station``).
        render_mode: ``"rgb_array"`` or ``None``.
    """

    metadata: ClassVar[dict] = {"render_modes": ["rgb_array"], "render_fps": 2}

    def __init__(
        self,
        config: Any = "default",
        overrides: dict | None = None,
        observation: str = "cloud",
        num_points: int = 4096,
        normals: bool = False,
        view_set: int | None = None,
        target_coverage: float = 0.6,
        max_views: int = 10,
        view_cost: float = 0.01,
        travel_cost: float = 0.0,
        min_elevation: float = math.radians(10.0),
        distance: tuple[float, float] = (0.5, 0.7),
        clampings: tuple[str, ...] = CLAMPINGS,
        density: float = 2e5,
        radius: float = 0.002,
        max_angle: float = 75.0,
        render_mode: str | None = None,
    ):
        if observation not in OBSERVATIONS:
            raise ValueError(f"observation = {observation!r} is not allowed: one of {OBSERVATIONS}")
        if num_points < 1:
            raise ValueError(f"num_points = {num_points} is not allowed: at least 1")
        if not 0.0 < target_coverage <= 1.0:
            raise ValueError(
                f"target_coverage = {target_coverage} is not allowed: above 0, at most 1"
            )
        if max_views < 1:
            raise ValueError(f"max_views = {max_views} is not allowed: at least 1")
        if not 0.0 <= min_elevation < math.pi / 2:
            raise ValueError(f"min_elevation = {min_elevation} is not allowed: 0 to below pi/2")
        if not clampings or any(c not in CLAMPINGS for c in clampings):
            raise ValueError(f"clampings = {clampings!r} is not allowed: some of {CLAMPINGS}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode = {render_mode!r} is not allowed: 'rgb_array' or None")
        if view_set is not None and view_set < 1:
            raise ValueError(f"view_set = {view_set} is not allowed: at least 1, or None")
        self.config = config
        self.observation = observation
        self.overrides = DEFAULT_OVERRIDES if overrides is None else overrides
        self.num_points = num_points
        self.normals = normals
        self.target_coverage = target_coverage
        self.max_views = max_views
        self.view_cost = view_cost
        self.travel_cost = travel_cost
        self.clampings = tuple(clampings)
        self.coverage_rule = {"density": density, "radius": radius, "max_angle": max_angle}
        self.render_mode = render_mode

        # the sensor's working range bounds the distances
        probe = Station(self.config, 0, self.clampings[0], self.overrides, density=1e3)
        near, far = probe.working_range
        lo, hi = distance
        if not near <= lo <= hi <= far:
            raise ValueError(
                f"distance = {distance} is not allowed: "
                f"within the sensor's working range {near} to {far} m"
            )
        self.low = np.array([-math.pi, min_elevation, lo, -math.pi], dtype=np.float32)
        self.high = np.array([math.pi, math.pi / 2, hi, math.pi], dtype=np.float32)
        if view_set is None:
            self.views = None
            # normalised: -1 to 1 spans each quantity's range
            self.action_space = spaces.Box(-1.0, 1.0, (4,), np.float32)
        else:
            self.views = sphere_views(view_set, min_elevation, (lo + hi) / 2)
            self.action_space = spaces.Discrete(view_set)
        self.observation_space = spaces.Dict(self._spaces())
        # the directions the vector observation's coverage is told by
        self.facings = np.array([_direction(v) for v in sphere_views(FACINGS, -math.pi / 2, 1.0)])
        self.station: Station | None = None
        # stations by (index, clamping), the most recently used last, each with (for the vector
        # observation) the direction each of its surface samples faces (an index into
        # `facings`) and how many face each
        self._stations: dict[tuple[int, str], tuple[Station, Any, Any]] = {}
        # the points, normals and view numbers of the episode's cloud (see `_add`)
        self._store = (
            np.zeros((0, 3), np.float32),
            np.zeros((0, 3), np.float32),
            np.zeros(0, np.int32),
        )

    def _spaces(self) -> dict:
        one = spaces.Box(0.0, 1.0, (1,), np.float32)
        if self.observation == "cloud":
            observed = {
                "points": spaces.Box(-EXTENT, EXTENT, (self.num_points, 3), np.float32),
                "new": spaces.MultiBinary(self.num_points),
                "coverage": one,
            }
            if self.normals:
                observed["normals"] = spaces.Box(-1.0, 1.0, (self.num_points, 3), np.float32)
        else:
            observed = {
                "coverage": one,
                "coverage_by_direction": spaces.Box(0.0, 1.0, (FACINGS,), np.float32),
                "occupancy": spaces.MultiBinary(GRID**3),
                "views": one,
            }
            if self.views is None:
                observed["poses"] = spaces.Box(-1.0, 1.0, (4 * self.max_views,), np.float32)
        if self.views is not None:
            observed["taken"] = spaces.MultiBinary(len(self.views))
        return observed

    # -- the episode ------------------------------------------------------------------------

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """A new motor and clamping, drawn from the seed; ``options`` may fix them:
        ``{"index": i, "clamping": "pole-pot-up"}`` (the motor of sample ``i``)."""
        super().reset(seed=seed)
        options = options or {}
        index = int(options.get("index", self.np_random.integers(0, 2**62)))
        clamping = options.get(
            "clamping", self.clampings[int(self.np_random.integers(len(self.clampings)))]
        )
        self.station, self._facing, self._facing_count = self._station(index, clamping)
        self.index, self.clamping = index, clamping
        self.centre = np.array(self.station.centre, dtype=np.float32)
        # the cloud so far: views into arrays kept from episode to episode and grown by
        # doubling, so that a step copies only its own points into pages already in use
        self.cloud, self.cloud_normals, self.cloud_view = (a[:0] for a in self._store)
        self.coverage = 0.0
        self.last_direction: np.ndarray | None = None
        self.taken = np.zeros(0 if self.views is None else len(self.views), np.int8)
        self.poses = np.zeros((self.max_views, 4), np.float32)
        self.occupancy = np.zeros(GRID**3, np.int8)
        return self._observation(), self._info(0.0)

    def _station(self, index: int, clamping: str) -> tuple[Station, Any, Any]:
        """The station of motor ``index`` in ``clamping`` with no view taken: one kept from an
        earlier episode, restarted (the same as a new one, without sampling its surface and
        building its world again), or a new one; with its samples' facings for the vector
        observation."""
        kept = self._stations.pop((index, clamping), None)
        if kept is None:
            station = Station(self.config, index, clamping, self.overrides, **self.coverage_rule)
            kept = (station, None, None)
            if self.observation == "vector":
                facing = np.argmax(station.surface()["normal"] @ self.facings.T, axis=1)
                kept = (station, facing, np.bincount(facing, minlength=FACINGS))
        else:
            kept[0].restart()
        self._stations[(index, clamping)] = kept
        while len(self._stations) > STATIONS_KEPT:
            del self._stations[next(iter(self._stations))]
        return kept

    def step(self, action):
        if self.station is None:
            raise RuntimeError("call reset() before step()")
        view = self.pose_of(action)
        n = self.station.views
        if self.views is not None:
            self.taken[int(action)] = 1
        elif n < self.max_views:
            self.poses[n] = np.clip(action, -1.0, 1.0)
        got = self.station.capture(*view)
        self._add(got["xyz"], got["normal"], n)
        self.coverage = self.station.coverage()[0]
        direction = _direction(view)
        travel = (
            0.0
            if self.last_direction is None
            else float(np.arccos(np.clip(direction @ self.last_direction, -1, 1)))
        )
        self.last_direction = direction
        reward = got["gain"] - self.view_cost - self.travel_cost * travel
        terminated = self.coverage >= self.target_coverage
        truncated = not terminated and self.station.views >= self.max_views
        info = self._info(got["gain"])
        info["travel"] = travel
        return self._observation(), float(reward), terminated, truncated, info

    def _add(self, xyz: np.ndarray, normals: np.ndarray, view: int) -> None:
        """Appends a view's points (world; centred on the motor as they go in), their normals and
        the view's number to the cloud, and for the vector observation marks the grid cells they
        occupy."""
        n, m = len(self.cloud), len(xyz)
        if n + m > len(self._store[0]):
            size = max(2 * len(self._store[0]), n + m, 1 << 16)
            grown = []
            for old in self._store:
                new = np.empty((size, *old.shape[1:]), old.dtype)
                new[:n] = old[:n]
                grown.append(new)
            self._store = tuple(grown)
        store_xyz, store_normals, store_view = self._store
        np.subtract(xyz, self.centre, out=store_xyz[n : n + m])
        store_normals[n : n + m] = normals
        store_view[n : n + m] = view
        self.cloud = store_xyz[: n + m]
        self.cloud_normals = store_normals[: n + m]
        self.cloud_view = store_view[: n + m]
        if self.observation != "vector":
            return
        cell = np.floor((store_xyz[n : n + m] + GRID_EXTENT) * (GRID / (2 * GRID_EXTENT)))
        cell = cell[((cell >= 0) & (cell < GRID)).all(axis=1)].astype(np.int64)
        self.occupancy[cell[:, 0] + GRID * (cell[:, 1] + GRID * cell[:, 2])] = 1

    def action_masks(self) -> np.ndarray:
        """The views that may be taken (True): those of the view set not taken yet, or every
        one when all are (SB3-contrib's ``MaskablePPO`` reads it)."""
        if self.views is None:
            raise ValueError(
                "action masks need a discrete view set: make the environment with view_set="
            )
        free = self.taken == 0
        return free if free.any() else np.ones_like(free)

    def pose_of(self, action) -> tuple[float, float, float, float]:
        """The view (azimuth, elevation, distance, roll) an action stands for: a view set's view, or
        each of the four from -1 to 1 across its range."""
        if self.views is not None:
            return tuple(float(x) for x in self.views[int(action)])
        a = np.clip(np.asarray(action, dtype=np.float32), -1.0, 1.0)
        return tuple(float(x) for x in self.low + (a + 1.0) / 2.0 * (self.high - self.low))

    def _observation(self) -> dict:
        obs = self._vector() if self.observation == "vector" else self._cloud()
        if self.views is not None:
            obs["taken"] = self.taken.copy()
        return obs

    def _vector(self) -> dict:
        seen = np.bincount(self._facing[self.station.seen], minlength=FACINGS)
        obs = {
            "coverage": np.array([self.coverage], np.float32),
            "coverage_by_direction": (seen / np.maximum(self._facing_count, 1)).astype(np.float32),
            "occupancy": self.occupancy.copy(),
            "views": np.array([min(self.station.views / self.max_views, 1.0)], np.float32),
        }
        if self.views is None:
            obs["poses"] = self.poses.flatten()
        return obs

    def _cloud(self) -> dict:
        n = len(self.cloud)
        if n == 0:
            pick = np.zeros(self.num_points, np.int64)
        else:
            pick = self.np_random.choice(n, self.num_points, replace=n < self.num_points)
        empty = n == 0
        points = np.zeros((self.num_points, 3), np.float32) if empty else self.cloud[pick]
        latest = self.station.views - 1 if self.station else -1
        new = (
            np.zeros(self.num_points, np.int8)
            if empty
            else (self.cloud_view[pick] == latest).astype(np.int8)
        )
        obs = {
            "points": np.clip(points, -EXTENT, EXTENT, out=points),
            "new": new,
            "coverage": np.array([self.coverage], np.float32),
        }
        if self.normals:
            normals = (
                np.zeros((self.num_points, 3), np.float32) if empty else self.cloud_normals[pick]
            )
            obs["normals"] = np.clip(normals, -1.0, 1.0, out=normals)
        return obs

    def _info(self, gain: float) -> dict:
        total, parts = self.station.coverage()
        return {
            "coverage": total,
            "coverage_per_part": dict(parts),
            "gain": gain,
            "views": self.station.views,
            "index": self.index,
            "clamping": self.clamping,
            "points": len(self.cloud),
        }

    # -- rendering ---------------------------------------------------------------------------

    def render(self):
        """The cloud so far as an RGB image (240 x 320), seen from above at 45 degrees: the
        latest view's points orange, the earlier ones blue, shaded by height."""
        if self.render_mode != "rgb_array":
            return None
        h, w = 240, 320
        image = np.full((h, w, 3), 24, np.uint8)
        if self.station is None or len(self.cloud) == 0:
            return image
        p = self.cloud
        # camera frame: x right, y down (towards the viewer's feet), z into the picture
        c, s = math.cos(math.pi / 4), math.sin(math.pi / 4)
        x = p[:, 0]
        y = -(c * p[:, 2] + s * p[:, 1])
        z = -s * p[:, 2] + c * p[:, 1]
        scale = min(h, w) / 0.3  # 30 cm across
        u = (w / 2 + scale * x).astype(int)
        v = (h / 2 + scale * y).astype(int)
        inside = (u >= 0) & (u < w) & (v >= 0) & (v < h)
        order = np.argsort(-z[inside])  # far first, near painted over it
        u, v = u[inside][order], v[inside][order]
        latest = (self.cloud_view == self.station.views - 1)[inside][order]
        shade = np.clip(0.5 + 4.0 * p[inside][order][:, 2], 0.3, 1.0)[:, None]
        colour = np.where(latest[:, None], [[255, 140, 30]], [[60, 130, 230]]) * shade
        image[v, u] = colour.astype(np.uint8)
        return image


def _direction(view) -> np.ndarray:
    azimuth, elevation = view[0], view[1]
    return np.array(
        [
            math.cos(elevation) * math.cos(azimuth),
            math.cos(elevation) * math.sin(azimuth),
            math.sin(elevation),
        ]
    )


# -- baselines -------------------------------------------------------------------------------


def random_view(env: gymnasium.Env) -> Any:
    """A view drawn uniformly from the action space (with the action space's own seed)."""
    return env.action_space.sample()


def greedy_view(env: gymnasium.Env) -> int:
    """The next-best view of a discrete view set: of the views not taken yet, the one from which
    an ideal sensor would see the most surface not yet covered (``Station.predict``; it knows
    the motor's surface)."""
    inner = env.unwrapped
    if inner.views is None:
        raise ValueError(
            "greedy_view needs a discrete view set: make the environment with view_set="
        )
    scores = [
        -1.0 if inner.taken[k] else inner.station.predict(*v) for k, v in enumerate(inner.views)
    ]
    return int(np.argmax(scores))


gymnasium.register(
    id="motorfactory/ViewPlanning-v0", entry_point="motorfactory.gym:ViewPlanningEnv"
)
