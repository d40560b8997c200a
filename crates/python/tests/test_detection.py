"""Detection datasets: each colour image's parts as torchvision's targets, exact against the
instance image, and torchvision's Mask R-CNN trains on them."""

import numpy as np
import torch
from torch.utils.data import DataLoader

import motorfactory as mf
from motorfactory.torch import DetectionDataset, detection_collate

# quarter-resolution scans: 612 x 512 colour images
FAST = {"sensor.sampling": "blueSubsample4x4"}


def test_detection_targets_are_the_parts_in_the_colour_image():
    data = DetectionDataset("default", split="train", samples=6, overrides=FAST)
    gen = mf.Generator("default", samples=6, overrides={**FAST, "output.images": True})
    assert data.num_classes == len(gen.classes) == 7
    image, target = data[0]
    view = gen[data.indices[0]]["views"][0]
    assert image.shape == (3, 512, 612) and image.dtype == torch.float32
    assert float(image.max()) <= 1.0 and float(image.max()) > 0.1
    np.testing.assert_array_equal((image * 255).round().byte().permute(1, 2, 0).numpy(), view["image"])
    k = len(target["labels"])
    assert k >= 3 and target["boxes"].shape == (k, 4) and target["masks"].shape == (k, 512, 612)
    assert target["image_id"] == data.indices[0]
    assert ((target["labels"] >= 1) & (target["labels"] < data.num_classes)).all()
    for box, mask, instance, label, area in zip(
        target["boxes"], target["masks"], target["instance"], target["labels"], target["area"]
    ):
        want = view["image_instance"] == int(instance)
        np.testing.assert_array_equal(mask.numpy().astype(bool), want)
        ys, xs = np.nonzero(want)
        # x0 y0 x1 y1 with the far edges one past the last pixel
        assert box.tolist() == [xs.min(), ys.min(), xs.max() + 1, ys.max() + 1]
        assert int(label) == int(view["image_label"][ys[0], xs[0]])
        assert float(area) == want.sum()


def test_mask_rcnn_runs_forward_and_backward_on_a_batch():
    from torchvision.models.detection import maskrcnn_resnet50_fpn

    torch.manual_seed(0)
    data = DetectionDataset("default", split="train", samples=4, overrides=FAST)
    loader = DataLoader(data, batch_size=2, collate_fn=detection_collate)
    images, targets = next(iter(loader))
    model = maskrcnn_resnet50_fpn(
        weights=None, weights_backbone=None, num_classes=data.num_classes, min_size=256, max_size=320
    )
    model.train()
    losses = model(list(images), list(targets))
    assert {"loss_classifier", "loss_box_reg", "loss_mask"} <= set(losses)
    total = sum(losses.values())
    assert torch.isfinite(total)
    total.backward()
    grads = [p.grad for p in model.parameters() if p.grad is not None]
    assert grads and any(float(g.abs().sum()) > 0 for g in grads)
