"""The type stubs against the extension module (mypy's stubtest, from the package registry), and
a docstring on everything the package offers."""

import importlib
import importlib.util
import inspect
import subprocess
import sys

import motorfactory as mf
import motorfactory.gym as mg
import motorfactory.nn as mnn
import motorfactory.sb3 as msb3
import motorfactory.torch as mt


def test_the_stubs_are_the_extension_modules():
    # PEP 800's disjoint bases are left out: the stubs support Python 3.9, before typing had them
    out = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "motorfactory._core", "--ignore-disjoint-bases"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stdout + out.stderr


def test_everything_offered_has_a_docstring():
    missing = []
    modules = [mf, mg, mnn, msb3, mt]
    if importlib.util.find_spec("ray") is not None:
        modules.append(importlib.import_module("motorfactory.ray"))
    for module in modules:
        assert module.__doc__, module.__name__
        names = getattr(module, "__all__", None) or [
            n for n, v in vars(module).items()
            if not n.startswith("_") and getattr(v, "__module__", None) == module.__name__
        ]
        for name in names:
            item = getattr(module, name)
            if not (inspect.isclass(item) or callable(item)):
                continue
            if not inspect.getdoc(item):
                missing.append(f"{module.__name__}.{name}")
            if inspect.isclass(item):
                for attr, member in vars(item).items():
                    public = not attr.startswith("_") or attr in ("__getitem__", "__len__")
                    if public and callable(member) or isinstance(member, property):
                        if not attr.startswith("_") and not inspect.getdoc(member):
                            missing.append(f"{module.__name__}.{name}.{attr}")
    assert missing == []
