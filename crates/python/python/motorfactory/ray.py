"""motorfactory on a Ray cluster (``pip install ./crates/python[ray]``).

- :func:`read_motorfactory`: a Ray Dataset of a configuration's samples, made in the read
  tasks by the Rust core, one row a sample, the arrays :class:`motorfactory.Generator` gives;
- :class:`MotorfactoryDatasource`: the datasource behind it, for ``ray.data.read_datasource``;
- :func:`write`: the dataset folder ``motorfactory generate`` writes, its shards written by
  Ray tasks.

Only the configuration (a dict) and each task's sample indices or shard travel to the
workers; every row and every file is the same whichever worker made it.
"""

import json
import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Union

import numpy as np
import ray.data
from ray.data import Datasource, ReadTask
from ray.data.block import Block, BlockAccessor, BlockMetadata

from . import Generator
from . import write as write_shard

__all__ = ["COLUMNS", "POINT_COLUMNS", "MotorfactoryDatasource", "read_motorfactory", "write"]

Config = Union[None, str, Mapping[str, Any]]

#: The per-point arrays of a sample's first view, as ``Generator[i]`` gives them.
POINT_COLUMNS = ("xyz", "normal", "intensity", "snr", "rgb", "label", "instance", "wear")

#: Every column a row may hold: the sample's index, its per-point arrays, and ``json``, the
#: sample's metadata (``samples/NNNNNN.json`` of ``motorfactory generate``) as a JSON string.
COLUMNS = ("index",) + POINT_COLUMNS + ("json",)


#: Each per-point column's bytes a point.
BYTES_PER_POINT = {
    "xyz": 12,
    "normal": 12,
    "intensity": 4,
    "snr": 4,
    "rgb": 3,
    "label": 2,
    "instance": 4,
    "wear": 4,
}

#: The points of a sample, as the datasource estimates them for Ray's memory budget (the
#: ``default`` configuration's samples hold about 185k).
ESTIMATED_POINTS = 200_000


class MotorfactoryDatasource(Datasource):
    """The samples ``indices`` of a configuration (``config``, ``seed`` and ``overrides`` as
    :class:`motorfactory.Generator` takes them), each read task a run of consecutive entries of
    ``indices``. ``num_points`` draws each sample's fixed-size block of points with replacement
    as :class:`motorfactory.torch.MotorDataset` does (the same points for the same ``seed`` and
    index); ``columns`` keeps those of :data:`COLUMNS` named."""

    def __init__(
        self,
        config: Config,
        indices: Sequence[int],
        *,
        seed: Optional[int] = None,
        overrides: Optional[Mapping[str, Any]] = None,
        num_points: Optional[int] = None,
        columns: Optional[Sequence[str]] = None,
    ) -> None:
        if num_points is not None and num_points < 1:
            raise ValueError(f"num_points = {num_points} is not allowed: expected at least 1")
        wanted = list(COLUMNS if columns is None else columns)
        unknown = [c for c in wanted if c not in COLUMNS]
        if unknown:
            raise ValueError(
                f"columns {unknown} are not allowed: expected some of {', '.join(COLUMNS)}"
            )
        self._config = _table(config, seed, overrides, None)
        self._indices = [int(i) for i in indices]
        self._seed = 0 if seed is None else seed
        self._num_points = num_points
        self._columns = wanted
        self._points = ESTIMATED_POINTS if num_points is None else num_points
        self._bytes_per_point = sum(BYTES_PER_POINT.get(c, 0) for c in wanted)

    def get_name(self) -> str:
        return "Motorfactory"

    def estimate_inmemory_data_size(self) -> Optional[int]:
        return self._size(len(self._indices))

    def _size(self, rows: int) -> int:
        """The estimated bytes of `rows` samples: without an estimate Ray budgets a block of
        its maximum size for every task and runs one task at a time."""
        return rows * self._points * self._bytes_per_point

    def get_read_tasks(
        self,
        parallelism: int,
        per_task_row_limit: Optional[int] = None,
        data_context: Any = None,
    ) -> List[ReadTask]:
        count = len(self._indices)
        tasks = max(1, min(parallelism, count))
        bounds = [count * t // tasks for t in range(tasks + 1)]
        read = []
        for start, stop in zip(bounds, bounds[1:]):
            if start == stop:
                continue
            chunk = self._indices[start:stop]
            meta = BlockMetadata(
                num_rows=len(chunk),
                size_bytes=self._size(len(chunk)),
                exec_stats=None,
                input_files=None,
            )
            read.append(
                ReadTask(
                    _reader(self._config, chunk, self._seed, self._num_points, self._columns),
                    meta,
                    per_task_row_limit=per_task_row_limit,
                )
            )
        return read


def _reader(
    config: Dict[str, Any],
    indices: List[int],
    seed: int,
    num_points: Optional[int],
    columns: List[str],
) -> Any:
    """A read task's work: its samples made by a generator built in the worker, a block each."""

    def read() -> Iterator[Block]:
        generator = Generator(config)  # its own count aside: sample i depends on i alone
        for index in indices:
            row = _row(generator.sample_at(index), index, seed, num_points)
            batch = {c: _one(row[c]) for c in columns}
            yield BlockAccessor.batch_to_block(batch)

    return read


def _row(sample: Mapping[str, Any], index: int, seed: int, num_points: Optional[int]) -> Dict[str, Any]:
    """A sample's columns: its index, first view's arrays (a block of them with
    ``num_points``) and metadata."""
    row: Dict[str, Any] = {c: sample[c] for c in POINT_COLUMNS}
    if num_points is not None:
        n = row["xyz"].shape[0]
        if n == 0:
            raise ValueError(f"sample {index} holds no point to draw from")
        pick = np.random.default_rng((seed, index)).integers(0, n, size=num_points)
        row = {c: v[pick] for c, v in row.items()}
    row["index"] = np.int64(index)
    row["json"] = json.dumps(sample["json"], sort_keys=True)
    return row


def _one(value: Any) -> np.ndarray:
    """A batch column of one row."""
    if isinstance(value, np.ndarray):
        return value[np.newaxis]
    return np.array([value])


def read_motorfactory(
    config: Config = "default",
    n: Optional[int] = None,
    seed: Optional[int] = None,
    *,
    overrides: Optional[Mapping[str, Any]] = None,
    split: Optional[str] = None,
    num_points: Optional[int] = None,
    columns: Optional[Sequence[str]] = None,
    parallelism: int = -1,
    num_cpus: Optional[float] = None,
    concurrency: Optional[int] = None,
    ray_remote_args: Optional[Dict[str, Any]] = None,
) -> "ray.data.Dataset":
    """The first ``n`` samples (the configuration's own count without it) of a configuration
    as a Ray Dataset, one row a sample: ``index``, the first view's per-point arrays as
    ``Generator[i]`` gives them (``xyz``, ``normal``, ``intensity``, ``snr``, ``rgb``,
    ``label``, ``instance``, ``wear``; a fixed-size block of them with ``num_points``, as
    :class:`motorfactory.torch.MotorDataset` draws it) and ``json``, the sample's metadata.
    ``split`` (``train`` or ``validation``) keeps that split's samples; ``columns`` keeps the
    columns named. ``parallelism`` (the number of read tasks, Ray's choice by default),
    ``num_cpus`` (a task's CPUs), ``concurrency`` (tasks at once) and ``ray_remote_args`` go to
    ``ray.data.read_datasource``."""
    generator = Generator(config, seed=seed, overrides=overrides, samples=n)
    indices = generator.indices(split)
    source = MotorfactoryDatasource(
        config,
        indices,
        seed=seed,
        overrides=overrides,
        num_points=num_points,
        columns=columns,
    )
    return ray.data.read_datasource(
        source,
        override_num_blocks=None if parallelism == -1 else parallelism,
        num_cpus=num_cpus,
        concurrency=concurrency,
        ray_remote_args=ray_remote_args,
    )


def _table(
    config: Config, seed: Optional[int], overrides: Optional[Mapping[str, Any]], n: Optional[int]
) -> Dict[str, Any]:
    """The whole configuration as a dict (what a Generator pickles as), so that workers need
    no file of the driver's."""
    return Generator(config, seed=seed, overrides=overrides, samples=n).__reduce__()[1][0]


def write(
    config: Config,
    n: Optional[int],
    out: Union[str, "os.PathLike[str]"],
    seed: Optional[int] = None,
    *,
    overrides: Optional[Mapping[str, Any]] = None,
    shards: Optional[int] = None,
    num_cpus: Optional[float] = None,
    max_retries: int = 3,
) -> Dict[str, int]:
    """Writes the dataset folder ``motorfactory generate`` writes (``n`` samples of a
    configuration, its own count for ``None``, into ``out``, a folder every node reaches), byte
    for byte, as ``shards`` Ray tasks (the cluster's CPUs by default), each :func:`motorfactory.write` of one shard with
    ``resume``: the shard that finishes last writes the merged manifest, and a task Ray retries
    after its worker died (up to ``max_retries`` times) makes only those of its own samples the
    dead one left. ``num_cpus`` is a task's CPUs. Returns the counts summed over the shards
    (``made``, ``skipped``, ``points``, ``empty``)."""
    table = _table(config, seed, overrides, n)
    count = shards if shards is not None else max(1, int(ray.cluster_resources().get("CPU", 1)))
    if count < 1:
        raise ValueError(f"shards = {count} is not allowed: expected at least 1")
    folder = os.path.abspath(out)
    cpus = 1 if num_cpus is None else num_cpus
    task = ray.remote(_write_one).options(num_cpus=cpus, max_retries=max_retries)
    done = ray.get([task.remote(table, folder, (i, count)) for i in range(count)])
    total = {"made": 0, "skipped": 0, "points": 0, "empty": 0}
    for counts in done:
        for key in total:
            total[key] += len(counts[key]) if key == "empty" else counts[key]
    return total


def _write_one(table: Dict[str, Any], out: str, shard: "tuple[int, int]") -> Dict[str, Any]:
    """A task's work: one shard of the dataset, resumed where a dead worker left it."""
    return write_shard(out, config=table, shard=shard, resume=True)
