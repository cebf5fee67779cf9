"""Where a scene's things must appear in a picture, worked out without the browser: a pinhole
projection of their meshes (three.js's ``PerspectiveCamera``: vertical field of view, square
pixels) filled triangle by triangle; and the pixels of a colour, found by hue."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw
from scipy import ndimage


def project(points, camera, rectangle, up=(0.0, 0.0, 1.0)):
    """Pixel positions (n, 2) of world ``points`` (n, 3) seen by ``camera`` (position, look_at,
    fov) drawn into ``rectangle`` (left, top, width, height)."""
    position, look_at, up = (np.asarray(v, dtype=float) for v in (camera.position, camera.look_at, up))
    back = position - look_at
    back /= np.linalg.norm(back)
    right = np.cross(up, back)
    right /= np.linalg.norm(right)
    above = np.cross(back, right)
    offset = np.asarray(points, dtype=float) - position
    x, y, depth = offset @ right, offset @ above, -(offset @ back)
    left, top, width, height = rectangle
    half = np.tan(camera.fov / 2)
    u = (x / depth) / (half * width / height)
    v = (y / depth) / half
    return np.column_stack([left + (u + 1) / 2 * width, top + (1 - v) / 2 * height])


def silhouette(meshes, camera, rectangle, size):
    """Where the meshes ``[(trimesh, world pose (4, 4)), ...]`` cover a picture of ``size``
    (width, height): a boolean mask (height, width)."""
    canvas = Image.new("L", size, 0)
    draw = ImageDraw.Draw(canvas)
    for mesh, pose in meshes:
        vertices = np.asarray(mesh.vertices) @ pose[:3, :3].T + pose[:3, 3]
        pixels = project(vertices, camera, rectangle)
        for face in np.asarray(mesh.faces):
            draw.polygon([tuple(p) for p in pixels[face]], fill=255)
    return np.asarray(canvas) > 0


def robot_meshes(scene, state):
    """The scene's robot (collision geometry) at ``state``: ``[(trimesh, world pose), ...]``."""
    poses = scene.frame_poses(np.asarray(state, dtype=float)[None])[0]
    return [(part.mesh, poses[frame] @ part.pose) for frame, part in scene.parts]


def hue_mask(image, low, high, saturation=0.35, value=0.25):
    """Pixels of ``image`` (h, w, 3) whose hue lies in ``[low, high]`` degrees, with at least the
    given saturation and value (0..1)."""
    rgb = image.astype(float) / 255.0
    top, bottom = rgb.max(axis=2), rgb.min(axis=2)
    spread = np.where(top > bottom, top - bottom, 1.0)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    hue = np.select(
        [top == r, top == g],
        [((g - b) / spread) % 6, (b - r) / spread + 2],
        (r - g) / spread + 4,
    )
    hue = np.where(top > bottom, hue * 60.0, -1.0)
    sat = np.where(top > 0, (top - bottom) / np.where(top > 0, top, 1.0), 0.0)
    return (hue >= low) & (hue <= high) & (sat >= saturation) & (top >= value)


def orange(image):
    """The robot's orange (style.ROBOT, shaded, also seen through translucent obstacles)."""
    return hue_mask(image, 12.0, 48.0)


def red(image):
    """The red of what collides (style.CONTACT), shaded towards crimson."""
    return hue_mask(image, 0.0, 8.0, saturation=0.5) | hue_mask(image, 335.0, 360.0, saturation=0.5)


def grown(mask, pixels=3):
    return ndimage.binary_dilation(mask, iterations=pixels)


def overlap(a, b):
    """Intersection over union of two masks."""
    union = (a | b).sum()
    return float((a & b).sum() / union) if union else 0.0
