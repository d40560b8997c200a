"""Motors: parts as arrays, ground truth as the CLI writes it, saving, bad input."""

import json
import subprocess

import numpy as np
import pytest

import motorfactory as mf


def test_parts_are_closed_meshes_with_labels():
    m = mf.motor(seed=1)
    assert len(m.parts) == len(m.attributes["attributes"]["parts"])
    names = set()
    for p in m.parts:
        v, t = p.vertices, p.triangles
        assert v.dtype == np.float32 and v.shape[1] == 3
        assert t.dtype == np.uint32 and t.shape[1] == 3 and t.max() < len(v)
        # every edge used twice, once each way, after welding equal positions
        _, weld = np.unique(v, axis=0, return_inverse=True)
        tri = weld.reshape(-1)[t]
        edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        forward = {tuple(e) for e in edges}
        assert all((b, a) in forward for a, b in edges), p.name
        assert p.instance >= 1 and p.name not in names
        names.add(p.name)
    kinds = {p.kind: p.class_id for p in m.parts}
    assert kinds["cover"] == 1 and kinds["gear_container"] == 2


def test_attributes_and_params_are_the_clis(cli, tmp_path):
    subprocess.run(
        [cli, "motor", "--random", "--seed", "7", "--set", "type=B", "--out", tmp_path],
        check=True,
        capture_output=True,
    )
    written = json.loads((tmp_path / "attributes.json").read_text())
    m = mf.motor({"type": "B"}, seed=7, random=True)
    assert m.attributes == written
    assert m.params == written["params"]
    assert m.params["type"] == "B"


def test_params_take_values_and_distributions():
    fixed = mf.motor({"type": "B", "mirror": True})
    assert fixed.params["type"] == "B" and fixed.params["mirror"] is True
    drawn = [mf.motor({"type": {"choice": ["A", "B"]}}, seed=s).params["type"] for s in range(12)]
    assert set(drawn) == {"A", "B"}
    assert mf.motor(seed=3, random=True).params == mf.motor(seed=3, random=True).params


def test_save_writes_the_formats_and_refuses_an_earlier_motor(tmp_path):
    m = mf.motor(seed=2)
    written = m.save(tmp_path, formats=["stl", "glb"])
    assert (tmp_path / "motor.stl").is_file() and (tmp_path / "cover.glb").is_file()
    assert len(written) == 2 * (1 + len(m.parts)) + 1
    with pytest.raises(ValueError, match="already holds a motor; pass replace=True"):
        m.save(tmp_path)
    m.save(tmp_path, formats=["ply"], per_part=False, replace=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["attributes.json", "motor.ply"]


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: mf.motor({"type": "C"}), ValueError, 'type = "C" is not allowed: expected one of "A", "B"'),
        (lambda: mf.motor({"gear_radiuss": 0.03}), ValueError, "unknown parameter `gear_radiuss`"),
        (lambda: mf.motor(detail="ultra"), ValueError, 'detail = "ultra" is not allowed: expected coarse, normal or fine'),
        (lambda: mf.motor({"type": object()}), ValueError, "type: a object is not allowed"),
        (lambda: mf.motor(seed=-1), OverflowError, ""),
        (lambda: mf.motor().save("/proc/motorfactory"), OSError, "/proc/motorfactory"),
        (lambda: mf.motor().save("/tmp", formats=["fbx"]), ValueError, "fbx"),
    ],
)
def test_bad_input_raises_with_the_clis_words(call, error, message):
    with pytest.raises(error) as raised:
        call()
    assert message in str(raised.value)
