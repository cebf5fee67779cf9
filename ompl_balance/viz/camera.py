"""Where the viewer's camera starts: :func:`framing` places it so that a box of the scene fills
the view. The viewer renders through it as three.js's ``PerspectiveCamera`` does (a pinhole with
a vertical field of view and square pixels, z up)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The camera's vertical field of view (degrees).
FIELD_OF_VIEW = 45.0


@dataclass(frozen=True)
class Camera:
    """Where the viewer's camera starts: ``position`` and ``look_at`` (3,) in metres, z up,
    ``fov`` the vertical field of view in radians."""

    position: np.ndarray
    look_at: np.ndarray
    fov: float


def framing(low: np.ndarray, high: np.ndarray, plane: bool) -> Camera:
    """A camera that sees the box ``low``..``high`` whole: from the front-left and above (a 2-D
    world: from above, tilted a little), at the distance where the box's bounding sphere fills
    the view's height."""
    centre = 0.5 * (low + high)
    radius = max(0.5 * float(np.linalg.norm(high - low)), 1e-3)
    direction = np.array([0.0, -0.45, 1.0]) if plane else np.array([1.0, -1.25, 0.75])
    fov = math.radians(FIELD_OF_VIEW)
    distance = 0.72 * radius / math.sin(0.5 * fov)  # (a box's corners seldom all face the camera)
    return Camera(centre + distance * direction / np.linalg.norm(direction), centre, fov)
