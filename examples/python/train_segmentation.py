"""Trains a small point-cloud segmentation network on motorfactory samples streamed from the
Rust core, on the CPU: a PointNet-style per-point network (shared MLPs, a max-pooled global
feature) on blocks of 2048 points, printing the loss and the validation mIoU as it goes.

    python examples/python/train_segmentation.py --steps 300

The last line is a JSON summary (first and last loss, final mIoU) for scripts.
"""

import argparse
import json
import time

import torch
from torch import nn
from torch.utils.data import DataLoader

import motorfactory as mf
from motorfactory.torch import MotorDataset, MotorStream


class PointNetSeg(nn.Module):
    """Per-point features (xyz and colour), a global max-pooled feature, per-point classes."""

    def __init__(self, classes: int) -> None:
        super().__init__()

        def mlp(*sizes: int) -> nn.Sequential:
            layers = []
            for a, b in zip(sizes, sizes[1:]):
                layers += [nn.Conv1d(a, b, 1), nn.BatchNorm1d(b), nn.ReLU()]
            return nn.Sequential(*layers)

        self.local = mlp(6, 64, 128)
        self.globe = mlp(128, 256)
        self.head = nn.Sequential(mlp(128 + 256, 128), nn.Conv1d(128, classes, 1))

    def forward(self, x: torch.Tensor) -> torch.Tensor:  # x: B x 6 x N
        local = self.local(x)
        pooled = self.globe(local).max(dim=2, keepdim=True).values
        return self.head(torch.cat([local, pooled.expand(-1, -1, x.shape[2])], dim=1))


def features(batch: dict) -> torch.Tensor:
    return torch.cat([batch["xyz"], batch["rgb"]], dim=2).transpose(1, 2)


def miou(model: nn.Module, loader: DataLoader, classes: int) -> float:
    """Mean intersection over union over the classes present in the validation samples."""
    model.eval()
    inter, union = torch.zeros(classes), torch.zeros(classes)
    with torch.no_grad():
        for batch in loader:
            pred = model(features(batch)).argmax(dim=1)
            for c in range(classes):
                p, t = pred == c, batch["label"] == c
                inter[c] += (p & t).sum()
                union[c] += (p | t).sum()
    model.train()
    present = union > 0
    return float((inter[present] / union[present]).mean())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default="default", help="a built-in configuration or a TOML file")
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--batch", type=int, default=8)
    ap.add_argument("--points", type=int, default=2048)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--sampling", default="blueSubsample4x4", help="the sensor's sampling, by Zivid's names (the M60: all, blueSubsample2x2, blueSubsample4x4, ...)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    torch.manual_seed(args.seed)
    overrides = {"sensor.sampling": args.sampling}
    classes = len(mf.Generator(args.config, overrides=overrides).classes)
    # training: the stream of the training split only; validation: the first samples of the
    # configuration's validation split, which the stream never yields, made once
    train = MotorStream(args.config, count=args.steps * args.batch, num_points=args.points,
                        normalize=True, seed=args.seed, overrides=overrides, split="train")
    val = MotorDataset(args.config, split="validation", num_points=args.points, normalize=True,
                       seed=args.seed, overrides=overrides)
    held_out = val.indices[:8]
    print(f"validation: samples {held_out}, of the validation split (training streams the "
          f"train split's)", flush=True)
    val_loader = DataLoader(torch.utils.data.Subset(val, range(len(held_out))), batch_size=4)

    model = PointNetSeg(classes)
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    loss_fn = nn.CrossEntropyLoss()
    losses = []
    start = time.perf_counter()
    loader = DataLoader(train, batch_size=args.batch, num_workers=args.workers)
    for step, batch in enumerate(loader, 1):
        loss = loss_fn(model(features(batch)), batch["label"])
        opt.zero_grad()
        loss.backward()
        opt.step()
        losses.append(loss.item())
        if step % 25 == 0 or step == args.steps:
            rate = step * args.batch / (time.perf_counter() - start)
            print(f"step {step:4d}  loss {sum(losses[-25:]) / len(losses[-25:]):.3f}  "
                  f"({rate:.1f} samples/s)", flush=True)
    score = miou(model, val_loader, classes)
    window = max(1, min(10, len(losses) // 4))
    first, last = sum(losses[:window]) / window, sum(losses[-window:]) / window
    print(f"validation mIoU {score:.3f}")
    print(json.dumps({"first_loss": first, "last_loss": last, "miou": score, "steps": len(losses),
                      "validation_samples": held_out}))


if __name__ == "__main__":
    main()
