"""Marionette from Python: characters loaded, posed, skinned and rendered in-process by the
same Rust code as the `marionette` binary, numpy arrays in and out.

    import marionette as mt
    c = mt.load("xbot.glb")
    p = c.pose(preset="sit-chair")
    out = mt.render(mt.Scene([c]), width=640, height=480, data=True)
"""

from pathlib import Path

from ._native import (  # noqa: F401
    Character,
    Error,
    FileError,
    Pose,
    PoseError,
    Scene,
    SpecError,
    load,
    render,
)
from . import _native

__all__ = [
    "Character", "Dataset", "Error", "FileError", "Pose", "PoseError", "Scene", "SpecError",
    "generate", "load", "render",
]


def generate(spec, shard=None, *, count=None, seed=None, out=None, batch=8):
    """The pictures of a data-set spec (`generate SPEC`), as dicts: `key` ("000042"), `rgb`,
    `coco` (and with the spec's `data`: `depth`, `normal`, `mask`, `camera`; with its
    `controlnet`: `controlnet`), the same pictures the binary makes. `shard=(i, n)` takes
    the pictures k with k mod n = i, as `--shard i/n`; `count` and `seed` override the
    spec's. Without `out` the pictures are drawn in memory, `batch` at a time, and yielded
    as they are drawn (nothing is written); with `out` they are written there as
    `generate SPEC --out OUT` writes them, then yielded."""
    shard_text = None if shard is None else f"{int(shard[0])}/{int(shard[1])}"
    if out is None:
        pictures = _native.SetPictures(str(spec), shard_text, count, seed)
        while True:
            drawn = pictures.draw(batch)
            if not drawn:
                return
            yield from drawn
    keys, data = _native.generate_pictures(str(spec), str(out), shard_text, count, seed)
    for key in keys:
        sample = _native.read_picture(str(Path(out) / f"{key}.png"), data)
        sample["key"] = key
        yield sample


def _torch_base():
    try:
        from torch.utils.data import IterableDataset
    except ImportError:
        return object
    return IterableDataset


class Dataset(_torch_base()):
    """A data-set spec as a dataset: `len(ds)` pictures, `iter(ds)` yields them as
    `generate` does. Where torch imports it is a `torch.utils.data.IterableDataset`, and each
    DataLoader worker draws its share of the pictures as `--shard` splits a set."""

    def __init__(self, spec, *, count=None, seed=None):
        self.spec, self.count, self.seed = str(spec), count, seed
        self._len = _native.spec_count(self.spec, count)

    def __len__(self):
        return self._len

    def __iter__(self):
        shard = None
        try:
            from torch.utils.data import get_worker_info

            info = get_worker_info()
            if info is not None:
                shard = (info.id, info.num_workers)
        except ImportError:
            pass
        return generate(self.spec, shard, count=self.count, seed=self.seed)
