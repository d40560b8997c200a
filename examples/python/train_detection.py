"""Fits torchvision's Mask R-CNN (no pretrained weights) to motorfactory's colour images on the
CPU: a few samples of a configuration made once, their parts' boxes, classes and masks as
targets, AdamW for a number of steps, printing the losses as it goes.

    python examples/python/train_detection.py --steps 40

The last line is a JSON summary (mean total loss over the first and the last five steps) for
scripts.
"""

import argparse
import json
import time

import torch
from torchvision.models.detection import maskrcnn_resnet50_fpn

from motorfactory.torch import DetectionDataset


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default="default", help="a built-in configuration or a TOML file")
    ap.add_argument("--samples", type=int, default=8, help="images fitted")
    ap.add_argument("--steps", type=int, default=40)
    ap.add_argument("--batch", type=int, default=2)
    ap.add_argument("--size", type=int, default=256, help="the model's shorter image side")
    ap.add_argument("--sampling", default="blueSubsample4x4", help="the sensor's sampling, by Zivid's names (the M60: all, blueSubsample2x2, blueSubsample4x4, ...)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    torch.manual_seed(args.seed)
    data = DetectionDataset(args.config, split=None, samples=args.samples, seed=args.seed,
                            overrides={"sensor.sampling": args.sampling})
    start = time.perf_counter()
    items = [data[k] for k in range(len(data))]
    print(f"{len(items)} images made in {time.perf_counter() - start:.1f} s, "
          f"{sum(len(t['labels']) for _, t in items)} parts")
    model = maskrcnn_resnet50_fpn(weights=None, weights_backbone=None, num_classes=data.num_classes,
                                  min_size=args.size, max_size=int(args.size * 1.25))
    model.train()
    # from scratch: Adam and clipped gradients keep the untrained heads from diverging
    optimiser = torch.optim.AdamW(model.parameters(), lr=1e-4)
    totals = []
    for step in range(args.steps):
        picked = [items[(step * args.batch + k) % len(items)] for k in range(args.batch)]
        losses = model([i for i, _ in picked], [t for _, t in picked])
        total = sum(losses.values())
        optimiser.zero_grad()
        total.backward()
        torch.nn.utils.clip_grad_norm_(model.parameters(), 5.0)
        optimiser.step()
        totals.append(float(total.detach()))
        parts = " ".join(f"{k[5:]} {float(v.detach()):.3f}" for k, v in losses.items())
        print(f"step {step + 1:3d}: loss {float(total):.3f} ({parts})", flush=True)
    head, tail = totals[:5], totals[-5:]
    print(json.dumps({"steps": args.steps, "first_loss": sum(head) / len(head),
                      "last_loss": sum(tail) / len(tail)}))


if __name__ == "__main__":
    main()
