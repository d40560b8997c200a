"""A contact sheet of a dataset's colour images with its COCO annotations drawn: each
instance's mask tinted in its class colour, its box outlined and its class named.

    python3 contact_sheet.py DATASET_DIR OUT.png [COLUMNS] [WIDTH]
"""

import json
import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw


def main():
    root, out = Path(sys.argv[1]), sys.argv[2]
    columns = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    width = int(sys.argv[4]) if len(sys.argv) > 4 else 480
    labels = {c["id"]: c for c in json.loads((root / "labels.json").read_text())["classes"]}
    tiles = []
    for split in ("train", "validation"):
        path = root / "annotations" / f"instances_{split}.json"
        if not path.exists():
            continue
        coco = json.loads(path.read_text())
        for image in coco["images"]:
            rgb = Image.open(root / image["file_name"]).convert("RGB")
            name = image["file_name"].rsplit("_rgb.", 1)[0] + "_instances.png"
            instances = np.array(Image.open(root / name))
            tint = np.array(rgb, dtype=np.float32)
            anns = [a for a in coco["annotations"] if a["image_id"] == image["id"]]
            for a in anns:
                colour = np.array(labels[a["category_id"]]["color"], dtype=np.float32)
                mask = instances == a["instance"]
                tint[mask] = 0.55 * tint[mask] + 0.45 * colour
            tile = Image.fromarray(tint.clip(0, 255).astype(np.uint8))
            draw = ImageDraw.Draw(tile)
            for a in anns:
                x, y, w, h = a["bbox"]
                colour = tuple(labels[a["category_id"]]["color"])
                draw.rectangle([x, y, x + w - 1, y + h - 1], outline=colour, width=3)
                draw.text((x + 3, y + 2), labels[a["category_id"]]["name"], fill=colour)
            scale = width / tile.width
            tiles.append(tile.resize((width, round(tile.height * scale)), Image.LANCZOS))
    rows = (len(tiles) + columns - 1) // columns
    height = max(t.height for t in tiles)
    sheet = Image.new("RGB", (columns * width, rows * height), "white")
    for k, t in enumerate(tiles):
        sheet.paste(t, ((k % columns) * width, (k // columns) * height))
    sheet.save(out)


if __name__ == "__main__":
    main()
