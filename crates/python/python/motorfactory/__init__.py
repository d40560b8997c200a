"""Synthetic, labelled 3D training data of small electric gear motors, made in-process.

- :func:`motor` builds a parametric gear motor (type A or B) with its parts as closed meshes;
- :func:`scan` scans meshes with a simulated sensor (Zivid, Kinect, ...);
- :class:`Generator` makes the samples of a dataset configuration, the values
  ``motorfactory generate`` writes, by index;
- :mod:`motorfactory.torch` streams them into PyTorch (``torch`` is optional);
- :class:`Station` clamps a motor at the inspection station and takes views of it one at a
  time, with the surface they cover; :mod:`motorfactory.gym` makes it a Gymnasium environment
  (``gymnasium`` is optional).
"""

from ._core import *  # noqa: F403 (the extension's names, as its __all__ lists them)
from ._core import __all__
