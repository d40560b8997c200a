"""PyTorch datasets of motorfactory samples, made on demand in the DataLoader's workers.

- :class:`MotorDataset`: a map-style dataset of one split of a configuration, optionally with
  fixed-size blocks of points as the AgiProbot networks take them;
- :class:`MotorStream`: an iterable dataset that shards the sample indices (of one split, or
  all) over DataLoader workers and distributed ranks, endless or for a number of samples;
- :class:`DetectionDataset`: a split's colour images with torchvision's detection targets
  (boxes, labels, masks), for Mask R-CNN and its kin;
- :func:`detection_collate`: batches detection samples as torchvision's models take them;
- :func:`collate`: batches clouds of different sizes into one, with a batch index per point;
- :func:`to_pyg`: a sample as a ``torch_geometric.data.Data`` (with PyTorch Geometric).

Every sample is a dict of tensors: ``xyz`` (N x 3 float32), ``rgb`` (N x 3 float32 in 0..1),
``label`` (N int64), ``instance`` (N int64), ``normal`` (N x 3 float32) and ``index`` (the
sample's index in the configuration). The points and labels are those ``motorfactory generate``
writes for that sample (its first view).
"""

from typing import Any, Callable, Dict, Iterator, List, Mapping, Optional, Union

import numpy as np
import torch
from torch.utils.data import Dataset, IterableDataset, get_worker_info

from . import Generator

Sample = Dict[str, Any]
Config = Union[None, str, Mapping[str, Any]]


def _tensors(sample: Mapping[str, Any], index: int) -> Sample:
    """A generator sample's first view as tensors."""
    return {
        "xyz": torch.from_numpy(sample["xyz"]),
        "rgb": torch.from_numpy(sample["rgb"].astype(np.float32) / 255.0),
        "label": torch.from_numpy(sample["label"].astype(np.int64)),
        "instance": torch.from_numpy(sample["instance"].astype(np.int64)),
        "normal": torch.from_numpy(sample["normal"]),
        "index": index,
    }


def block(sample: Sample, num_points: int, seed: Any, normalize: bool = False) -> Sample:
    """``num_points`` of the sample's points drawn with replacement (the same for the same
    ``seed``, anything ``numpy.random.default_rng`` takes), as the AgiProbot networks take their 2048 or 4096 points; with ``normalize``,
    centred on their mean and scaled into the unit sphere."""
    n = sample["xyz"].shape[0]
    if n == 0:
        raise ValueError(f"sample {sample['index']} holds no point to draw from")
    rng = np.random.default_rng(seed)
    pick = torch.from_numpy(rng.integers(0, n, size=num_points))
    out = {k: (v[pick] if torch.is_tensor(v) else v) for k, v in sample.items()}
    if normalize:
        xyz = out["xyz"] - out["xyz"].mean(dim=0)
        out["xyz"] = xyz / xyz.norm(dim=1).max().clamp_min(1e-12)
    return out


class MotorDataset(Dataset):
    """The samples of one split (``train`` or ``validation``, as the configuration's
    ``augment.validation`` share assigns them; ``None``: every sample) of a configuration, made
    when asked for.

    ``num_points`` draws a fixed-size block of each sample's points with replacement (the same
    block every time for the same sample and ``seed``), ``normalize`` scales it into the unit
    sphere, and ``transform`` is applied to each sample's dict last. ``config``, ``seed`` and
    ``overrides`` are those of :class:`motorfactory.Generator`.
    """

    def __init__(
        self,
        config: Config = "default",
        split: Optional[str] = "train",
        num_points: Optional[int] = None,
        normalize: bool = False,
        transform: Optional[Callable[[Sample], Any]] = None,
        seed: Optional[int] = None,
        overrides: Optional[Mapping[str, Any]] = None,
        samples: Optional[int] = None,
    ) -> None:
        self.generator = Generator(config, seed=seed, overrides=overrides, samples=samples)
        self.indices: List[int] = self.generator.indices(split)
        if num_points is not None and num_points < 1:
            raise ValueError(f"num_points = {num_points} is not allowed: expected at least 1")
        self.num_points = num_points
        self.normalize = normalize
        self.transform = transform
        self.seed = 0 if seed is None else seed

    def __len__(self) -> int:
        return len(self.indices)

    def __getitem__(self, k: int) -> Any:
        index = self.indices[k]
        sample = _tensors(self.generator[index], index)
        if self.num_points is not None:
            sample = block(sample, self.num_points, (self.seed, index), self.normalize)
        return self.transform(sample) if self.transform is not None else sample


class MotorStream(IterableDataset):
    """The samples of a configuration from index ``start`` on, of one ``split`` (``train`` or
    ``validation``, as the configuration's ``augment.validation`` share assigns every index; the
    default ``None`` keeps every sample), endless without ``count`` (the number of samples
    streamed), shared out over the DataLoader's workers and the distributed ranks: worker ``w``
    of ``W`` on rank ``r`` of ``R`` makes the samples whose position in the stream is
    ``r * W + w`` modulo ``R * W``, so every sample is made once and a run is the same whatever
    the workers. Sample indices may exceed the configuration's ``samples`` (sample i does not
    depend on how many there are), and a training stream never yields a validation sample.
    """

    def __init__(
        self,
        config: Config = "default",
        start: int = 0,
        count: Optional[int] = None,
        num_points: Optional[int] = None,
        normalize: bool = False,
        transform: Optional[Callable[[Sample], Any]] = None,
        seed: Optional[int] = None,
        overrides: Optional[Mapping[str, Any]] = None,
        split: Optional[str] = None,
    ) -> None:
        self.generator = Generator(config, seed=seed, overrides=overrides)
        if split not in (None, "train", "validation"):
            raise ValueError(f'split = "{split}" is not allowed: expected "train" or "validation"')
        self.split = split
        self.start, self.count = start, count
        self.num_points, self.normalize, self.transform = num_points, normalize, transform
        self.seed = 0 if seed is None else seed

    def _share(self) -> "tuple[int, int]":
        """This worker's position among all workers of all ranks, and their number."""
        info = get_worker_info()
        worker, workers = (info.id, info.num_workers) if info is not None else (0, 1)
        dist = torch.distributed
        if dist.is_available() and dist.is_initialized():
            rank, ranks = dist.get_rank(), dist.get_world_size()
        else:
            rank, ranks = 0, 1
        return rank * workers + worker, ranks * workers

    def _indices(self) -> Iterator[int]:
        """The stream's sample indices, in order: from ``start``, those of its split."""
        index = self.start
        while True:
            if self.split is None or self.generator.split_of(index) == self.split:
                yield index
            index += 1

    def __iter__(self) -> Iterator[Any]:
        me, everyone = self._share()
        for k, index in enumerate(self._indices()):
            if self.count is not None and k >= self.count:
                return
            if k % everyone != me:
                continue
            sample = _tensors(self.generator.sample_at(index), index)
            if self.num_points is not None:
                sample = block(sample, self.num_points, (self.seed, index), self.normalize)
            yield self.transform(sample) if self.transform is not None else sample


def detection_target(view: Mapping[str, Any], index: int) -> "tuple[torch.Tensor, Dict[str, torch.Tensor]]":
    """A view's colour image (3 x H x W float32 in 0..1) and its target in torchvision's
    detection convention: ``boxes`` (K x 4 float32, x0 y0 x1 y1 in pixels, a pixel one unit
    wide), ``labels`` (K int64, the scheme's class ids; 0, the background, is never an
    object), ``masks`` (K x H x W uint8), ``instance`` (K int64, as in ``instances.png``),
    ``area`` (K float32, pixels), ``iscrowd`` (K int64, zeros) and ``image_id`` (the sample's
    index), one object per motor part in sight."""
    labels = view["image_label"]
    instances = view["image_instance"]
    ids = np.unique(instances[labels != 0])
    masks = instances[None, :, :] == ids[:, None, None]
    boxes = np.zeros((len(ids), 4), dtype=np.float32)
    classes = np.zeros(len(ids), dtype=np.int64)
    for k, mask in enumerate(masks):
        ys, xs = np.nonzero(mask)
        boxes[k] = [xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]
        classes[k] = labels[ys[0], xs[0]]
    image = torch.from_numpy(np.ascontiguousarray(view["image"].transpose(2, 0, 1))).float() / 255.0
    target = {
        "boxes": torch.from_numpy(boxes),
        "labels": torch.from_numpy(classes),
        "masks": torch.from_numpy(masks.astype(np.uint8)),
        "instance": torch.from_numpy(ids.astype(np.int64)),
        "area": torch.from_numpy(masks.sum(axis=(1, 2)).astype(np.float32)),
        "iscrowd": torch.zeros(len(ids), dtype=torch.int64),
        "image_id": index,
    }
    return image, target


class DetectionDataset(Dataset):
    """The colour images of one split of a configuration with their detection targets
    (:func:`detection_target`), made when asked for, in-process like :class:`MotorDataset`:
    each sample's first view, its images asked of the configuration (``output.images``).
    ``transform`` takes and returns ``(image, target)``. ``num_classes`` counts the scheme's
    classes with the background, as torchvision's models take it."""

    def __init__(
        self,
        config: Config = "default",
        split: Optional[str] = "train",
        transform: Optional[Callable[[Any, Any], Any]] = None,
        seed: Optional[int] = None,
        overrides: Optional[Mapping[str, Any]] = None,
        samples: Optional[int] = None,
    ) -> None:
        overrides = {**(overrides or {}), "output.images": True}
        self.generator = Generator(config, seed=seed, overrides=overrides, samples=samples)
        self.indices: List[int] = self.generator.indices(split)
        self.transform = transform
        self.num_classes = len(self.generator.classes)

    def __len__(self) -> int:
        return len(self.indices)

    def __getitem__(self, k: int) -> Any:
        index = self.indices[k]
        image, target = detection_target(self.generator[index]["views"][0], index)
        return self.transform(image, target) if self.transform is not None else (image, target)


def detection_collate(batch: List[Any]) -> Any:
    """Batches ``(image, target)`` pairs as torchvision's detection models take them: a tuple
    of images and a tuple of targets."""
    return tuple(zip(*batch))


def collate(batch: List[Sample]) -> Sample:
    """Batches samples of any sizes: their points concatenated, with ``batch`` giving each
    point's sample and ``offsets`` where each sample's points start (PyTorch Geometric's
    layout); ``index`` is the samples' indices."""
    sizes = [s["xyz"].shape[0] for s in batch]
    out = {
        k: torch.cat([s[k] for s in batch])
        for k in batch[0]
        if torch.is_tensor(batch[0][k])
    }
    out["batch"] = torch.repeat_interleave(
        torch.arange(len(batch)), torch.tensor(sizes, dtype=torch.int64)
    )
    out["offsets"] = torch.tensor([0] + sizes[:-1], dtype=torch.int64).cumsum(0)
    out["index"] = torch.tensor([s["index"] for s in batch], dtype=torch.int64)
    return out


def to_pyg(sample: Sample) -> Any:
    """A sample as ``torch_geometric.data.Data``: ``pos`` the points, ``x`` their colours,
    ``y`` the labels, ``normal`` and ``instance`` as they are (needs PyTorch Geometric)."""
    try:
        from torch_geometric.data import Data
    except ImportError as e:
        raise ImportError("to_pyg needs PyTorch Geometric: pip install torch_geometric") from e
    return Data(
        pos=sample["xyz"],
        x=sample["rgb"],
        y=sample["label"],
        normal=sample["normal"],
        instance=sample["instance"],
        index=sample["index"],
    )
