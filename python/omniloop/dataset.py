"""Truth datasets: frames of a camera with their depth, labels and poses, as ``omniloop
dataset`` writes them (``docs/truth.md``), made and read back with NumPy alone::

    import omniloop
    from omniloop import dataset

    omniloop.write_dataset("scenarios/corner55_velocity_aware.toml", "data/corner", samples=100)
    ds = dataset.load("data/corner")
    sample = ds[0]          # image, depth_mm, labels, pose, t_s
    names = {e["label"]: e["name"] for e in ds.legend}

- ``write_dataset(scenario, out, samples=100, poses="random", sensor=None, renderer="cpu",
  seed=None)``: poses ``"random"`` (over the floor, clear of every solid and robot) or
  ``"along-run"`` (the scenario's own run); returns ``dataset.json``'s content.
- ``load(path)`` gives a ``Dataset``: ``len(ds)``, ``ds[i]``, iteration, and ``info``
  (``dataset.json``), ``legend`` (``legend.json``: ``label``, ``class``, ``instance``,
  ``name``, ``rgb``), ``poses`` (``N x 3``: ``x_mm``, ``y_mm``, ``theta_rad``), ``t_s``,
  ``camera_model`` (``camera.yaml``, the fitted unified model of a mirror camera, or ``None``)
  and ``calibration`` (``calibration.json``, the image-to-floor map, or ``None``).
- A sample is a dict: ``"image"`` (``uint8`` ``H x W x 3``, the frame as the robot's software
  gets it), ``"depth_mm"`` (``float32`` ``H x W``: how far the light travelled to the camera,
  mirror included; NaN where the file holds 0, i.e. the sky or no mirror), ``"labels"``
  (``uint8``, or ``uint16`` past 256 labels: label numbers of ``legend``), ``"pose"``
  (``(x_mm, y_mm, theta_rad)``, the robot's true pose) and ``"t_s"``.

The PNGs are read by the native module (palette indices as stored, not colours); a missing
file raises ``FileNotFoundError`` (an ``OSError``), a file that is not such a PNG
``ValueError``, each naming the file.
"""

from __future__ import annotations

import csv
import json
import os
from pathlib import Path
from typing import Any, Iterator, Optional, Union

import numpy as np

from ._omniloop import Scenario, read_png_levels, read_png_rgb
from ._omniloop import write_dataset as _write_dataset

FORMAT = "omniloop-truth-dataset"
VERSION = 1

PathLike = Union[str, "os.PathLike[str]"]


def write_dataset(
    scenario: Union[Scenario, PathLike],
    out: PathLike,
    samples: int = 100,
    poses: str = "random",
    sensor: Optional[str] = None,
    renderer: str = "cpu",
    seed: Optional[int] = None,
) -> dict[str, Any]:
    """Writes ``samples`` frames of ``scenario``'s camera (``sensor``, default: the one vision
    uses, else the robot's first) with their truth into the folder ``out``, as ``omniloop
    dataset`` does: poses ``"random"`` or ``"along-run"``, with ``seed`` (default: the
    scenario's) on ``renderer``. ``scenario`` is an ``omniloop.Scenario`` or a path. Returns
    ``dataset.json``'s content."""
    if not isinstance(scenario, Scenario):
        scenario = Scenario.load(scenario)
    return _write_dataset(
        scenario, out, samples=samples, poses=poses, sensor=sensor, renderer=renderer, seed=seed
    )


def _read_json(path: Path) -> Any:
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except json.JSONDecodeError as e:
        raise ValueError(f"{path}: not JSON: {e}") from e


def _read_poses(path: Path) -> tuple[list[int], np.ndarray, np.ndarray]:
    """``poses.csv``: the sample numbers, ``t_s`` and the ``N x 3`` poses."""
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    try:
        samples = [int(r["sample"]) for r in rows]
        t_s = np.array([float(r["t_s"]) for r in rows], dtype=np.float64)
        poses = np.array(
            [[float(r["x_mm"]), float(r["y_mm"]), float(r["theta_rad"])] for r in rows],
            dtype=np.float64,
        ).reshape(-1, 3)
    except (KeyError, TypeError, ValueError) as e:
        raise ValueError(
            f"{path}: expected the columns sample,t_s,x_mm,y_mm,theta_rad ({e})"
        ) from e
    return samples, t_s, poses


class Dataset:
    """A truth dataset's folder (see the module's documentation); samples are read from their
    files when asked for."""

    def __init__(self, path: PathLike) -> None:
        self.path = Path(path)
        self.info: dict[str, Any] = _read_json(self.path / "dataset.json")
        if self.info.get("format") != FORMAT or self.info.get("version") != VERSION:
            raise ValueError(
                f"{self.path / 'dataset.json'}: not an {FORMAT} of version {VERSION} "
                f"(format {self.info.get('format')!r}, version {self.info.get('version')!r})"
            )
        files = self.info["files"]
        self.legend: list[dict[str, Any]] = _read_json(self.path / files["legend"])
        self._samples, self.t_s, self.poses = _read_poses(self.path / files["poses"])
        self._images = self.path / files["images"]
        self._depth = self.path / files["depth"]
        self._labels = self.path / files["labels"]
        self.camera_model: Optional[Path] = self._optional(files.get("camera_model"))
        self.calibration: Optional[Path] = self._optional(files.get("calibration"))

    def _optional(self, name: Optional[str]) -> Optional[Path]:
        return None if name is None else self.path / name

    def __len__(self) -> int:
        return len(self._samples)

    def __getitem__(self, index: int) -> dict[str, Any]:
        n = len(self)
        i = int(index) + n if int(index) < 0 else int(index)
        if not 0 <= i < n:
            raise IndexError(f"sample {index} of a dataset of {n}")
        name = f"{self._samples[i]:06d}.png"
        image = read_png_rgb(self._images / name)
        levels = read_png_levels(self._depth / name)
        depth = levels.astype(np.float32)
        depth[levels == 0] = np.nan
        labels = read_png_levels(self._labels / name)
        if len(self.legend) <= 256:
            labels = labels.astype(np.uint8)
        if not image.shape[:2] == depth.shape == labels.shape:
            raise ValueError(
                f"{self.path}: sample {name}: image {image.shape[:2]}, depth {depth.shape} "
                f"and labels {labels.shape} differ in size"
            )
        x, y, theta = (float(v) for v in self.poses[i])
        return {
            "image": image,
            "depth_mm": depth,
            "labels": labels,
            "pose": (x, y, theta),
            "t_s": float(self.t_s[i]),
        }

    def __iter__(self) -> Iterator[dict[str, Any]]:
        for i in range(len(self)):
            yield self[i]

    def __repr__(self) -> str:
        w, h = self.info.get("size_px", ["?", "?"])
        return (
            f"Dataset({str(self.path)!r}, scenario={self.info.get('scenario')!r}, "
            f"sensor={self.info.get('sensor')!r}, samples={len(self)}, size={w}x{h})"
        )


def load(path: PathLike) -> Dataset:
    """The truth dataset in the folder ``path`` (``dataset.json`` and its files)."""
    return Dataset(path)


__all__ = ["Dataset", "FORMAT", "VERSION", "load", "write_dataset"]
