"""The live viewer: a viser server showing a plan in the browser, with controls.

:class:`LiveViewer` draws the scene and plan (:class:`~ompl_balance.viz.render.Drawing`) on a
server listening on ``host`` (``127.0.0.1`` by default: this machine only) and adds a panel: the
problem and how its solve ended, a frame slider and a play button for the path, switches for the
layers, and what is closest to the robot (or in contact) at the frame shown. The animation plays
in a thread of its own; :meth:`LiveViewer.wait` blocks until Ctrl-C and then stops the server.
"""

from __future__ import annotations

import contextlib
import io
import threading
import time
from collections.abc import Callable

import numpy as np

from ..collision.contacts import describe_contacts
from .extra import require_viser
from .plan import Plan
from .scene import Scene

#: Frames a second the play button shows.
FRAMES_PER_SECOND = 30.0


class LiveViewer:
    """A running viewer of ``scene`` and ``plan`` (see the module docstring).

    Parameters
    ----------
    scene, plan:
        What to show.
    frames:
        The animation's states (m, state size).
    trees:
        Draw the plan's trees (a switch in the panel hides them).
    host, port:
        Where the server listens (``port`` 0: a free port the system picks); ``"0.0.0.0"`` shares
        the viewer with the network.
    """

    def __init__(
        self,
        scene: Scene,
        plan: Plan,
        frames: np.ndarray,
        trees: bool = False,
        host: str = "127.0.0.1",
        port: int = 8080,
    ) -> None:
        viser = require_viser()
        from .render import Drawing

        with contextlib.redirect_stdout(io.StringIO()):  # viser's banner: the caller prints the address
            self.server = viser.ViserServer(host=host, port=port, verbose=False)
        try:  # (the server is running: stopped if the rest fails, a Ctrl-C included)
            self.host = host
            self.port = int(self.server.get_port())
            self.scene, self.plan = scene, plan
            self.drawing = Drawing(self.server, scene, plan, frames, trees)
            self._lock = threading.Lock()
            self._playing = threading.Event()
            self._stopped = threading.Event()
            gui = self.server.gui
            # the panel beside the view, not over it; no share button (it would open a public tunnel)
            gui.configure_theme(show_share_button=False)
            gui.main_panel.dock_right()
            gui.add_markdown(self._summary())
            count = max(len(frames), 1)
            self._slider = gui.add_slider("frame", min=0, max=count - 1, step=1, initial_value=0, disabled=count < 2)
            self._play = gui.add_button("play", disabled=count < 2)
            self._readout = gui.add_markdown(self._closest(0))
            self._slider.on_update(lambda _event: self._show(int(self._slider.value)))
            self._play.on_click(lambda _event: self._toggle())
            ends = gui.add_checkbox("start and goal", True)
            ends.on_update(lambda _event: self._locked(self.drawing.show_ends, ends.value))
            for label, prefix in (("path", "/path"), ("trees", "/trees")):
                if self.drawing.nodes(prefix):
                    box = gui.add_checkbox(label, True)
                    box.on_update(lambda _event, box=box, prefix=prefix: self._layer(prefix, box.value))
            if scene.visuals:
                visual = gui.add_checkbox("visual meshes (else collision geometry)", True)
                visual.on_update(lambda _event: self._visuals(visual.value))
            self._thread = threading.Thread(target=self._animate, name="ompl-balance viewer", daemon=True)
            self._thread.start()
        except BaseException:
            with contextlib.redirect_stdout(io.StringIO()):
                self.server.stop()
            raise

    @property
    def url(self) -> str:
        """The address to open (``localhost`` for a server shared on all interfaces)."""
        host = "localhost" if self.host in ("0.0.0.0", "::") else self.host
        return f"http://{host}:{self.port}"

    @property
    def frame(self) -> int:
        """The animation frame shown; setting it moves the robot (and the slider)."""
        return self.drawing.frame

    @frame.setter
    def frame(self, k: int) -> None:
        if self._slider.value == int(k):
            self._show(int(k))
        else:
            self._slider.value = int(k)  # (its callback shows the frame)

    def play(self, playing: bool = True) -> None:
        """Start (or stop) the animation."""
        if playing:
            self._playing.set()
        else:
            self._playing.clear()
        self._play.label = "pause" if playing else "play"

    def present(self, open_browser: bool = True, wait: bool = True) -> None:
        """Say where the viewer is and open it in the browser (``open_browser``), then (``wait``)
        wait until Ctrl-C. Anything raised on the way, a Ctrl-C before the wait included, stops
        the server before it goes on."""
        try:
            if wait:
                print(f"showing {self.scene.title} at {self.url} (Ctrl-C to stop)", flush=True)
            if open_browser:
                import webbrowser

                webbrowser.open(self.url)
            if wait:
                self.wait()
        except BaseException:
            self.stop()
            raise

    def wait(self) -> None:
        """Block until Ctrl-C (or :meth:`stop` from another thread), then stop the server."""
        try:
            while not self._stopped.wait(0.2):
                pass
        except KeyboardInterrupt:
            pass
        finally:
            self.stop()

    def stop(self) -> None:
        """Stop the animation and the server (once)."""
        if self._stopped.is_set():
            return
        self._stopped.set()
        self._playing.clear()
        self._thread.join(timeout=2.0)
        with contextlib.redirect_stdout(io.StringIO()):
            self.server.stop()

    # -- internals

    def _summary(self) -> str:
        scene, plan = self.scene, self.plan
        lines = [f"**{scene.title}**"]
        if plan.planner or plan.status:
            lines.append(f"{plan.planner}: {plan.status}".strip(": "))
        if len(plan.path):
            lines.append(f"path of {len(plan.path)} states; the line traces the {scene.tip}")
        lines += [f"{label} {problem}" for label, state in (("start", plan.start), ("goal", plan.goal))
                  if state is not None and (problem := scene.problem(state))]  # fmt: skip
        lines += scene.notes
        return "  \n".join(lines)

    def _closest(self, k: int) -> str:
        frames = self.drawing.frames
        if not len(frames) or self.scene.state_size == 0:
            return ""
        contacts = self.scene.collisions(frames[min(k, len(frames) - 1)], nearest=1)
        if not contacts:
            return ""
        what = "in contact" if contacts[0].touching else "closest"
        return f"frame {k}, {what}: {describe_contacts(contacts, limit=3)}"

    def _show(self, k: int) -> None:
        with self._lock:
            self.drawing.show_frame(k)
            # the nearest pair costs FCL's distances of every pair: worked out when the robot stops
            self._readout.content = "" if self._playing.is_set() else self._closest(self.drawing.frame)

    def _toggle(self) -> None:
        self.play(not self._playing.is_set())
        if not self._playing.is_set():
            self._show(self.drawing.frame)

    def _locked(self, change: Callable[[bool], None], value: bool) -> None:
        with self._lock:
            change(value)

    def _layer(self, prefix: str, visible: bool) -> None:
        with self._lock:
            for node in self.drawing.nodes(prefix):
                node.visible = visible

    def _visuals(self, visual: bool) -> None:
        with self._lock:
            for name, node in self.drawing.handles.items():
                if name.startswith("/robot/") and "/visual/" in name:
                    node.visible = visual
                elif name.startswith("/robot/") and "/collision/" in name:
                    node.visible = not visual

    def _animate(self) -> None:
        count = len(self.drawing.frames)
        while not self._stopped.is_set():
            if not self._playing.wait(0.1) or count < 2:
                continue
            began = time.monotonic()
            self._slider.value = (self.drawing.frame + 1) % count  # (its callback shows the frame)
            time.sleep(max(0.0, 1.0 / FRAMES_PER_SECOND - (time.monotonic() - began)))
