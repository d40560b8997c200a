"""Trains the segmentation network of ``train_segmentation.py`` with Ray Train: a
``TorchTrainer`` of two workers (PyTorch's DistributedDataParallel over gloo, on the CPU), each
reading its share of the training split from ``read_motorfactory`` (Ray Train splits it
into equal shares, leaving out up to one sample a worker an epoch) (the samples made by the Rust
core in Ray Data's read tasks), printing the loss as it goes and the validation mIoU at the end.

    pip install "./crates/python[ray]"
    python examples/python/train_segmentation_ray.py --samples 400 --epochs 2

The last line is a JSON summary (first and last loss, final mIoU, the samples each worker read)
for scripts.
"""

import argparse
import json
import logging
import os
import tempfile

import ray
import ray.train
import torch
from ray.train import RunConfig, ScalingConfig
from ray.train.torch import TorchTrainer, prepare_model
from torch import nn
from torch.utils.data import DataLoader, Subset
from train_segmentation import PointNetSeg, miou

import motorfactory as mf
from motorfactory.ray import read_motorfactory
from motorfactory.torch import MotorDataset


def features(batch: dict) -> torch.Tensor:
    """What ``train_segmentation.py`` feeds its network: each block of points centred and
    scaled into the unit sphere (as ``MotorStream(normalize=True)`` does) with its colour in
    0..1, as B x 6 x N."""
    xyz = batch["xyz"] - batch["xyz"].mean(dim=1, keepdim=True)
    xyz = xyz / xyz.norm(dim=2).amax(dim=1).clamp_min(1e-12)[:, None, None]
    rgb = batch["rgb"].float() / 255.0
    return torch.cat([xyz, rgb], dim=2).transpose(1, 2)


def train_loop(config: dict) -> None:
    """One worker's training: its shard of the dataset, the model wrapped for DDP."""
    torch.manual_seed(config["seed"])
    model = prepare_model(PointNetSeg(config["classes"]))
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    loss_fn = nn.CrossEntropyLoss()
    shard = ray.train.get_dataset_shard("train")
    losses, read = [], 0
    for epoch in range(config["epochs"]):
        for batch in shard.iter_torch_batches(batch_size=config["batch"]):
            loss = loss_fn(model(features(batch)), batch["label"].long())
            opt.zero_grad()
            loss.backward()
            opt.step()
            losses.append(loss.item())
            read += len(batch["index"])
        rank = ray.train.get_context().get_world_rank()
        print(f"worker {rank} epoch {epoch}: {len(losses)} steps, loss "
              f"{sum(losses[-10:]) / len(losses[-10:]):.3f}", flush=True)
    # the validation split's first samples (which the training split never holds), made in
    # the worker by the in-process dataset
    val = MotorDataset(config["config"], split="validation", num_points=config["points"],
                       normalize=True, seed=config["seed"], overrides=config["overrides"])
    held_out = Subset(val, range(min(8, len(val))))
    score = miou(model, DataLoader(held_out, batch_size=4), config["classes"])
    window = max(1, min(10, len(losses) // 4))
    total = torch.tensor([read])
    torch.distributed.all_reduce(total)  # the samples all workers read
    metrics = {
        "first_loss": sum(losses[:window]) / window,
        "last_loss": sum(losses[-window:]) / window,
        "steps": len(losses),
        "miou": score,
        "samples_read": int(total),
        "validation_samples": val.indices[: len(held_out)],
    }
    # the trained weights, from the first worker (DDP keeps every worker's alike)
    with tempfile.TemporaryDirectory() as folder:
        checkpoint = None
        if ray.train.get_context().get_world_rank() == 0:
            torch.save(model.module.state_dict(), os.path.join(folder, "model.pt"))
            checkpoint = ray.train.Checkpoint.from_directory(folder)
        ray.train.report(metrics, checkpoint=checkpoint)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default="default", help="a built-in configuration or a TOML file")
    ap.add_argument("--samples", type=int, default=400, help="samples of the configuration (the training split of them is read)")
    ap.add_argument("--epochs", type=int, default=2)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--points", type=int, default=2048)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cpus", type=int, default=4, help="the local cluster's CPUs to schedule: one a training worker, the rest for Ray Data's read tasks")
    ap.add_argument("--sampling", default="blueSubsample4x4", help="the sensor's sampling, by Zivid's names")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    ray.init(num_cpus=args.cpus, include_dashboard=False, logging_level=logging.WARNING)
    ray.data.DataContext.get_current().enable_progress_bars = False
    overrides = {"sensor.sampling": args.sampling}
    classes = len(mf.Generator(args.config, overrides=overrides).classes)
    train = read_motorfactory(args.config, n=args.samples, seed=args.seed, overrides=overrides,
                              split="train", num_points=args.points,
                              columns=["index", "xyz", "rgb", "label"])
    trainer = TorchTrainer(
        train_loop,
        train_loop_config={
            "config": args.config, "overrides": overrides, "classes": classes,
            "epochs": args.epochs, "batch": args.batch, "points": args.points, "seed": args.seed,
        },
        scaling_config=ScalingConfig(num_workers=args.workers, use_gpu=False),
        datasets={"train": train},
        run_config=RunConfig(storage_path=tempfile.mkdtemp(prefix="motorfactory-ray-train-")),
    )
    result = trainer.fit()
    summary = dict(result.metrics, workers=args.workers, checkpoint=result.checkpoint.path)
    ray.shutdown()  # the workers' last log lines printed before the summary
    print(f"validation mIoU {summary['miou']:.3f}; the weights in {summary['checkpoint']}/model.pt")
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
