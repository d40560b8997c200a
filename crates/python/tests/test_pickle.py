"""Pickling: every object a user may hand to another process round-trips, and a DataLoader's
workers started by ``spawn`` (which pickles the dataset) give what the main process gives."""

import pickle

import numpy as np
import torch
from torch.utils.data import DataLoader

import motorfactory as mf
from motorfactory.torch import MotorDataset


def test_a_generator_pickles_as_its_configuration():
    g = mf.Generator("default", seed=7, overrides={"camera.views": 2}, samples=5)
    copy = pickle.loads(pickle.dumps(g))
    assert len(copy) == 5
    assert copy.config == g.config
    a, b = g[3], copy[3]
    assert a["json"] == b["json"]
    for key in ("xyz", "normal", "label", "instance", "rgb"):
        assert np.array_equal(a[key], b[key]), key
    # the seed travels with it: another seed makes another sample
    other = mf.Generator("default", seed=8, overrides={"camera.views": 2}, samples=5)
    assert not np.array_equal(other[3]["xyz"], b["xyz"])


def test_a_station_pickles_with_its_views_and_goes_on_alike():
    st = mf.Station("default", 4, "pole-pot-up", density=5e4)
    st.capture(0.3, 0.6, 0.6)
    st.capture(2.0, 0.9, 0.55, 0.2)
    copy = pickle.loads(pickle.dumps(st))
    assert copy.views == 2
    assert copy.coverage() == st.coverage()
    assert np.array_equal(copy.seen, st.seen)
    assert copy.capture(1.0, 0.4, 0.6)["gain"] == st.capture(1.0, 0.4, 0.6)["gain"]
    # a restarted station pickles without the views it forgot
    st.restart()
    assert pickle.loads(pickle.dumps(st)).views == 0


def test_a_motor_and_its_parts_pickle():
    m = mf.motor(seed=3, random=True, detail="coarse")
    copy = pickle.loads(pickle.dumps(m))
    assert copy.params == m.params
    assert copy.attributes == m.attributes
    for a, b in zip(m.parts, copy.parts):
        assert (a.name, a.kind, a.class_id, a.instance) == (b.name, b.kind, b.class_id, b.instance)
        assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.triangles, b.triangles)
    part = pickle.loads(pickle.dumps(m.parts[2]))
    assert part.name == m.parts[2].name
    assert np.array_equal(part.vertices, m.parts[2].vertices)
    assert part.vertices.dtype == np.float32 and part.triangles.dtype == np.uint32


def test_a_scan_pickles_to_the_bit():
    v = np.array([[-0.3, -0.3, 0], [0.3, -0.3, 0], [0.3, 0.3, 0.05], [-0.3, 0.3, 0]], np.float32)
    t = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
    s = mf.scan([(v, t, 3, 9)], sensor="zivid-2plus-m60", eye=(0.1, 0, 0.6), target=(0, 0, 0), up=(0, 1, 0))
    copy = pickle.loads(pickle.dumps(s))
    for name in ("xyz", "normal", "depth", "label", "instance", "intensity", "pose"):
        a, b = getattr(s, name), getattr(copy, name)
        assert a.dtype == b.dtype and a.tobytes() == b.tobytes(), name
    for key, value in s.points().items():
        assert value.tobytes() == copy.points()[key].tobytes(), key
    assert repr(copy) == repr(s)


def test_dataloader_workers_started_by_spawn_give_the_same_batches():
    ds = MotorDataset("default", split=None, num_points=256, samples=4)
    spawned = list(DataLoader(ds, batch_size=2, num_workers=2, multiprocessing_context="spawn"))
    here = list(DataLoader(ds, batch_size=2))
    assert len(spawned) == len(here) == 2
    for x, y in zip(spawned, here):
        assert torch.equal(x["xyz"], y["xyz"]) and torch.equal(x["label"], y["label"])
