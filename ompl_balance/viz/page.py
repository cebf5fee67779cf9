"""One self-contained HTML file of a plan: viser's viewer and the recorded animation, offline.

viser (1.1 and later) records what a server's scene receives and writes it into a copy of its
web client (``StateSerializer.as_html``): one file holding the viewer's code and the scene,
compressed, that a browser opens from disk with no network and no Python. The recording's
timeline is the animation: the robot's moves at their times, played by viser's play/pause
button and time slider (the scene panel beside them shows and hides the layers).
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .camera import Camera
from .extra import require_viser
from .plan import Plan
from .scene import Scene

#: Seconds of an animation per frame (30 frames a second) ...
FRAME_SECONDS = 1.0 / 30.0
#: ... and seconds the robot stays at the goal before the animation starts again.
HOLD_SECONDS = 1.0


@dataclass(frozen=True)
class Page:
    """A written file: its ``path``, the animation's ``frames`` (m, state size), the time (s) of
    frame ``k`` being ``k * frame_seconds``, and the ``camera`` it opens with."""

    path: Path
    frames: np.ndarray
    frame_seconds: float
    camera: Camera


def write_page(scene: Scene, plan: Plan, frames: np.ndarray, file: str | Path, trees: bool = False) -> Page:
    """Write ``scene``, ``plan`` and the animation through ``frames`` (m, state size) to ``file``
    (one HTML file, see the module docstring)."""
    viser = require_viser()
    from .render import Drawing

    path = Path(file)
    quiet = io.StringIO()  # viser prints its address on start and stop: not a server anyone visits
    with contextlib.redirect_stdout(quiet):
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        drawing = Drawing(server, scene, plan, frames, trees)
        recording = server.get_scene_serializer()
        for k in range(1, len(frames)):
            recording.insert_sleep(FRAME_SECONDS)
            drawing.show_frame(k)
        if len(frames) > 1:
            recording.insert_sleep(HOLD_SECONDS)
        html = recording.as_html()
    finally:
        with contextlib.redirect_stdout(quiet):
            server.stop()
    path.write_text(html, encoding="utf-8")
    return Page(path, frames, FRAME_SECONDS, drawing.camera)
