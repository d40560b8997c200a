"""Scans: the organized arrays, meshes as files or arrays, bad input."""

import numpy as np
import pytest

import motorfactory as mf


def plane(z: float, half: float = 0.3):
    v = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    return v, t


def test_a_plane_scanned_from_above():
    v, t = plane(0.0)
    s = mf.scan([(v, t, 3, 9)], sensor="zivid-2plus-m60", eye=(0, 0, 0.6), target=(0, 0, 0), up=(0, 1, 0))
    h, w = s.depth.shape
    assert s.xyz.shape == (h, w, 3) and s.label.dtype == np.uint16
    valid = ~np.isnan(s.depth)
    assert valid.mean() > 0.5
    # at 0.6 m, within the preset's noise
    assert abs(np.nanmedian(s.depth) - 0.6) < 1e-3
    assert set(np.unique(s.label[valid])) == {3} and set(np.unique(s.instance[valid])) == {9}
    points = s.points()
    assert points["xyz"].shape == (valid.sum(), 3)
    np.testing.assert_array_equal(points["xyz"], s.xyz[valid])
    # the same seed, the same scan
    again = mf.scan([(v, t, 3, 9)], sensor="zivid-2plus-m60", eye=(0, 0, 0.6), target=(0, 0, 0), up=(0, 1, 0))
    np.testing.assert_array_equal(again.xyz, s.xyz)


def test_meshes_from_files(tmp_path):
    m = mf.motor()
    m.save(tmp_path, formats=["stl"], per_part=False)
    s = mf.scan([tmp_path / "motor.stl"], sensor="zivid-2plus-m60", eye=(0.1, -0.4, 0.45),
                target=(0, 0, 0.05), sampling="blueSubsample4x4")
    assert s.depth.shape == (512, 612)
    assert (~np.isnan(s.depth)).sum() > 1000


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: mf.scan([plane(0)], sensor="zivid-3"), ValueError, 'sensor "zivid-3" is not allowed: expected a preset'),
        (lambda: mf.scan([plane(0)], sampling="by3x3"), ValueError, "by3x3"),
        (lambda: mf.scan([plane(0)], material="gold"), ValueError, "gold"),
        (lambda: mf.scan([plane(0)], eye=(0, 0, 0), target=(0, 0, 0)), ValueError, "eye and target must differ"),
        (lambda: mf.scan(["/no/such.stl"]), OSError, "/no/such.stl"),
        (lambda: mf.scan([(np.zeros((3, 2), np.float32), np.zeros((1, 3), np.uint32), 1, 1)]), ValueError, "3 columns"),
        (lambda: mf.scan([(np.zeros((3, 3), np.float32), np.full((1, 3), 5, np.uint32), 1, 1)]), ValueError, "uses vertex 5"),
        (lambda: mf.scan([42]), ValueError, "a mesh is a file path or a"),
    ],
)
def test_bad_input_raises_with_the_clis_words(call, error, message):
    with pytest.raises(error) as raised:
        call()
    assert message in str(raised.value)
