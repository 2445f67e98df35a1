"""A mirror camera's image unwarped into a panorama strip, for learning (and for looking).

A catadioptric image spends most of its pixels where a policy learns nothing (outside the
mirror, the robot's own reflection), turns the robot's yaw into a rotation of the image and
shrinks distant things toward the centre. The panorama resamples it on a grid of azimuth
(across) and elevation or floor distance (down), through a lookup table built once from the
camera's model (``Scenario.camera_model``: Mei's unified model fitted to a mirror's traced
rays, or a calibrated or pinhole camera's intrinsics)::

    import omniloop
    from omniloop.panorama import Panorama

    scenario = omniloop.Scenario.load("scenarios/blackout_stage1.toml")
    pano = Panorama.of(scenario, width_px=128, height_px=16, elevation_deg=(-35.0, 5.0))
    strip = pano(obs.frames["omni"])          # (16, 128, 3) uint8; batches (N, H, W, 3) too

Columns: column ``j``'s centre looks at azimuth ``pi - (j + 0.5) * 2 pi / W`` in the body
frame (counter-clockwise from forward): the robot's back at both edges, its left a quarter
in, forward in the middle, its right three quarters in, as a person on the robot sees it.
The robot's heading is a circular shift of the columns: a turn on the spot by ``dtheta``
counter-clockwise moves everything ``dtheta * W / (2 pi)`` columns to the right
(``Panorama.columns(dtheta)``).

Rows: from the top, elevations from ``elevation_deg[1]`` down to ``elevation_deg[0]`` (the
viewpoint's, degrees above the horizon), or with ``floor_mm=(near, far)`` floor points from
``far`` down to ``near`` mm from the robot's centre (the floor's grid: a thing on the floor at a
given distance is on the same row whatever its azimuth).

Each cell averages ``samples x samples`` nearest pixels spread over it, so that a ball smaller
than a cell still tints it. Cells whose rays leave the image are black (``valid`` is False).
"""

from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np
import numpy.typing as npt

from . import Scenario

__all__ = ["Panorama", "yaw_augment"]


class Panorama:
    """The lookup table from one camera's image to its panorama (see the module's
    documentation); call it on an ``H x W x 3`` image or an ``N x H x W x 3`` batch."""

    def __init__(
        self,
        camera_model: dict[str, Any],
        width_px: int = 128,
        height_px: int = 16,
        elevation_deg: Sequence[float] = (-35.0, 5.0),
        floor_mm: Optional[Sequence[float]] = None,
        samples: int = 2,
    ) -> None:
        if not (isinstance(width_px, int) and 4 <= width_px <= 4096):
            raise ValueError(f"width_px={width_px!r}: an int from 4 to 4096")
        if not (isinstance(height_px, int) and 1 <= height_px <= 1024):
            raise ValueError(f"height_px={height_px!r}: an int from 1 to 1024")
        if not (isinstance(samples, int) and 1 <= samples <= 8):
            raise ValueError(f"samples={samples!r}: an int from 1 to 8")
        self.width_px, self.height_px, self.samples = width_px, height_px, samples
        self.image_size_px = tuple(int(v) for v in camera_model["image_size_px"])  # (w, h)
        s = samples
        # Sub-sample offsets within a cell, in cells: centred, s per axis.
        offsets = (np.arange(s) + 0.5) / s - 0.5
        cols = (np.arange(width_px)[:, None] + 0.5 + offsets[None, :]).reshape(-1)
        rows = (np.arange(height_px)[:, None] + 0.5 + offsets[None, :]).reshape(-1)
        #: Azimuth of each column's centre, rad, counter-clockwise from forward.
        self.azimuth_rad = math.pi - (np.arange(width_px) + 0.5) * 2.0 * math.pi / width_px
        azimuth = math.pi - cols * 2.0 * math.pi / width_px
        points = _row_points(rows / height_px, elevation_deg, floor_mm, camera_model)
        self.elevation_rad: Optional[npt.NDArray[np.float64]] = None
        self.floor_mm: Optional[npt.NDArray[np.float64]] = None
        centres = (np.arange(height_px) + 0.5) / height_px
        if floor_mm is None:
            lo, hi = (math.radians(float(v)) for v in elevation_deg)
            self.elevation_rad = hi - centres * (hi - lo)
        else:
            near, far = (float(v) for v in floor_mm)
            self.floor_mm = far - centres * (far - near)
        # (rows * s, cols * s, 3) points or directions in the body frame.
        horizontal, z, is_point = points
        body = np.empty((len(rows), len(cols), 3))
        body[..., 0] = horizontal[:, None] * np.cos(azimuth)[None, :]
        body[..., 1] = horizontal[:, None] * np.sin(azimuth)[None, :]
        body[..., 2] = z[:, None]
        u, v, ok = _project(camera_model, body, is_point)
        w, h = self.image_size_px
        iu, iv = np.rint(u), np.rint(v)
        ok &= (iu >= 0) & (iu < w) & (iv >= 0) & (iv < h)
        index = np.where(ok, iv * w + iu, 0).astype(np.intp)
        # Cell-major order: (H, W, s*s), so that the cell's samples are summed at once.
        shape = (height_px, s, width_px, s)
        index = index.reshape(shape).transpose(0, 2, 1, 3).reshape(height_px, width_px, s * s)
        seen = ok.reshape(shape).transpose(0, 2, 1, 3).reshape(height_px, width_px, s * s)
        #: Whether each cell sees the image (False: its rays leave it; the cell is black).
        self.valid: npt.NDArray[np.bool_] = np.asarray(seen.any(axis=-1))
        # A sample off the image takes a sample of its cell's that is on it (the cell averages
        # the ones on it); a cell with none is blacked out by `valid`.
        first = np.take_along_axis(index, seen.argmax(axis=-1)[..., None], axis=-1)
        # Slot-major, (s*s, H, W): each slot of every cell is one contiguous block.
        slots = np.moveaxis(np.where(seen, index, first), -1, 0).reshape(-1)
        # Byte offsets of each slot's red, green and blue in a flattened H x W x 3 image.
        self._index = (slots[:, None] * 3 + np.arange(3)).reshape(-1)
        self._mask = self.valid.astype(np.uint16)[..., None]

    @classmethod
    def of(
        cls, scenario: Scenario, sensor: Optional[str] = None, robot: Optional[str] = None,
        **kwargs: Any,
    ) -> "Panorama":
        """The panorama of camera ``sensor`` of ``robot`` in ``scenario`` (defaults: the first
        of each); ``kwargs`` as the constructor's."""
        return cls(scenario.camera_model(sensor, robot), **kwargs)

    @property
    def shape(self) -> tuple[int, int, int]:
        """The strip's shape: ``(height_px, width_px, 3)``."""
        return (self.height_px, self.width_px, 3)

    def __call__(self, image: npt.NDArray[np.uint8]) -> npt.NDArray[np.uint8]:
        img = np.asarray(image)
        w, h = self.image_size_px
        if img.shape[-3:] != (h, w, 3):
            raise ValueError(
                f"an image of shape {img.shape}: this panorama's camera gives {h} x {w} x 3"
            )
        lead = img.shape[:-3]
        flat = img.reshape(lead + (h * w * 3,))
        n = self.samples * self.samples
        picked = np.take(flat, self._index, axis=-1).reshape(lead + (n, -1))
        total = np.add.reduce(picked, axis=-2, dtype=np.uint16)
        total += n // 2
        if n & (n - 1) == 0:  # a power of two: a shift is the division, and cheaper
            total >>= n.bit_length() - 1
        else:
            total //= n
        out = total.reshape(lead + (self.height_px, self.width_px, 3))
        out *= self._mask
        strip: npt.NDArray[np.uint8] = out.astype(np.uint8)
        return strip

    def columns(self, yaw_rad: float) -> float:
        """How many columns a counter-clockwise turn of the robot by ``yaw_rad`` moves
        everything to the right."""
        return yaw_rad * self.width_px / (2.0 * math.pi)


def _row_points(
    fraction: npt.NDArray[np.float64],
    elevation_deg: Sequence[float],
    floor_mm: Optional[Sequence[float]],
    model: dict[str, Any],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], bool]:
    """For rows at ``fraction`` of the strip's height from its top: the horizontal length and
    height of each row's direction (elevation, from the viewpoint) or floor point (from the
    robot's centre, body frame), and whether they are points."""
    if floor_mm is not None:
        near, far = _band(floor_mm, "floor_mm", 0.0, math.inf)
        return far - fraction * (far - near), np.zeros_like(fraction), True
    lo, hi = _band(elevation_deg, "elevation_deg", -90.0, 90.0)
    e = np.radians(hi - fraction * (hi - lo))
    return np.cos(e), np.sin(e), False


def _band(band: Sequence[float], name: str, low: float, high: float) -> tuple[float, float]:
    try:
        a, b = (float(v) for v in band)
    except (TypeError, ValueError):
        raise ValueError(f"{name}={band!r}: two numbers (low, high)") from None
    if not (math.isfinite(a) and math.isfinite(b) and low <= a < b <= high):
        raise ValueError(f"{name}={band!r}: two finite numbers, {low} <= low < high <= {high}")
    return a, b


def _project(
    model: dict[str, Any], body: npt.NDArray[np.float64], is_point: bool
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
    """Pixel coordinates (OpenCV's: a pixel's centre at integers) of body-frame points or
    directions ``body`` (``... x 3``) through ``model``, and where they are in front of it."""
    frame = model["model_frame_in_body"]
    rotation = np.asarray(frame["rotation"], dtype=np.float64)  # columns: model axes in body
    rel = body - np.asarray(frame["translation_mm"]) if is_point else body
    x = rel @ rotation  # body -> model frame: R^T p, row-wise
    intr = model["intrinsics"]
    (fx, fy), (cx, cy) = intr["focal_px"], intr["principal_point_px"]
    if "xi" not in intr:  # a pinhole camera
        z = x[..., 2]
        ok = z > 1e-9
        zs = np.where(ok, z, 1.0)
        return fx * x[..., 0] / zs + cx, fy * x[..., 1] / zs + cy, ok
    # Mei's unified model (C. Mei and P. Rives, ICRA 2007, eqs. 1-4): the point on the unit
    # sphere, projected from (0, 0, -xi), then OpenCV omnidir's radial-tangential distortion.
    xs = x / np.linalg.norm(x, axis=-1, keepdims=True)
    xi = float(intr["xi"])
    den = xs[..., 2] + xi
    ok = den > 1e-9
    den = np.where(ok, den, 1.0)
    mx, my = xs[..., 0] / den, xs[..., 1] / den
    k1, k2, p1, p2 = intr.get("distortion_k1_k2_p1_p2", (0.0, 0.0, 0.0, 0.0))
    r2 = mx * mx + my * my
    radial = 1.0 + k1 * r2 + k2 * r2 * r2
    dx = mx * radial + 2.0 * p1 * mx * my + p2 * (r2 + 2.0 * mx * mx)
    dy = my * radial + p1 * (r2 + 2.0 * my * my) + 2.0 * p2 * mx * my
    skew = float(intr.get("skew_px", 0.0))
    return fx * dx + skew * dy + cx, fy * dy + cy, ok


def yaw_augment(
    strip: npt.NDArray[Any], velocity: Sequence[float] | npt.NDArray[Any], shift_columns: int
) -> tuple[npt.NDArray[Any], npt.NDArray[np.float64]]:
    """A panorama (``... x H x W x C``) and a body-frame velocity label ``(vx, vy[, omega])``
    as they would be had the world been turned about the robot by ``beta = 2 pi *
    shift_columns / W`` counter-clockwise: the strip rolled ``shift_columns`` columns to the
    left (every azimuth up by ``beta``) and ``(vx, vy)`` rotated by ``beta`` (``omega``
    unchanged). Learning to drive toward what it sees, a policy gets every heading from one."""
    a = np.asarray(strip)
    width = a.shape[-2]
    k = int(shift_columns)
    beta = 2.0 * math.pi * k / width
    v = np.array(velocity, dtype=np.float64)
    if v.shape[-1] not in (2, 3):
        raise ValueError(f"velocity of shape {v.shape}: (vx, vy) or (vx, vy, omega) last")
    c, s = math.cos(beta), math.sin(beta)
    vx, vy = v[..., 0].copy(), v[..., 1].copy()
    v[..., 0], v[..., 1] = c * vx - s * vy, s * vx + c * vy
    return np.roll(a, -k, axis=-2), v
