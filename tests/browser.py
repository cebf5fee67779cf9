"""Headless Chromium for the viewer's tests: open a page, let its picture settle, click, take screenshots.

Chromium is driven through the Chrome DevTools Protocol over a WebSocket (``websockets``, which
viser brings), with the flags that work on a machine without a GPU or a network: SwiftShader's
software WebGL, and no background connections (which a closed network refuses). Tests that need
the browser take :func:`chromium_or_skip`: where Debian's ``chromium`` is missing they skip and
say so.

:class:`Playback` works viser's playback bar in a written file: it waits for the recording,
pauses it at a chosen time with a click on the time slider, and reads the time it shows.

Run as a script, it takes the picture of a written file the docs show::

    python tests/browser.py plan.html docs/picture.png --at 0.55 --size 960x600
"""

from __future__ import annotations

import argparse
import base64
import contextlib
import io
import itertools
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np

#: Chromium's flags: headless, no sandbox (root in CI), software WebGL, no connections of its own.
FLAGS = (
    "--headless=new",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
    "--hide-scrollbars",
)


def chromium() -> str | None:
    """The Chromium executable on this machine, or ``None``."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


def chromium_or_skip() -> str:
    """The Chromium executable; skips the calling test, saying why, when there is none."""
    import pytest

    found = chromium()
    if found is None:
        pytest.skip("Chromium is not installed (apt-get install chromium): the browser tests cannot run here")
    return found


class Browser:
    """A headless Chromium with one page, ``width`` x ``height`` CSS pixels; use it in ``with``."""

    def __init__(self, width: int = 1000, height: int = 700, executable: str | None = None) -> None:
        from websockets.sync.client import connect

        executable = executable or chromium()
        if executable is None:
            raise RuntimeError("Chromium is not installed (apt-get install chromium)")
        # (Chromium's helper processes may still write to the profile as it is removed: a
        # leftover file there is no failure of the test)
        self._profile = tempfile.TemporaryDirectory(prefix="ompl-balance-chromium-", ignore_cleanup_errors=True)
        self.process = subprocess.Popen(
            [
                executable,
                *FLAGS,
                f"--user-data-dir={self._profile.name}",
                f"--window-size={width},{height}",
                "--remote-debugging-port=0",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,  # its own process group: closing ends its helpers too
        )
        port_file = Path(self._profile.name) / "DevToolsActivePort"
        deadline = time.monotonic() + 30
        while not (port_file.is_file() and port_file.read_text().strip()):
            if time.monotonic() > deadline or self.process.poll() is not None:
                self.close()
                raise RuntimeError("Chromium did not start")
            time.sleep(0.05)
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as answer:
            targets = json.loads(answer.read())
        page = next(t for t in targets if t["type"] == "page")
        self._socket = connect(page["webSocketDebuggerUrl"], max_size=None, open_timeout=10)
        self._ids = itertools.count(1)
        self.call("Page.enable")

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        """End Chromium (this object's process group only) and remove its profile."""
        socket = getattr(self, "_socket", None)
        if socket is not None:
            socket.close()
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        with contextlib.suppress(ProcessLookupError):
            os.killpg(self.process.pid, signal.SIGKILL)  # helpers left behind
        self._profile.cleanup()

    def call(self, method: str, **params: object) -> dict:
        """One DevTools command; its result (``RuntimeError`` for an error)."""
        number = next(self._ids)
        self._socket.send(json.dumps({"id": number, "method": method, "params": params}))
        while True:
            message = json.loads(self._socket.recv(timeout=120))
            if message.get("id") == number:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message["result"]

    def open(self, url: str) -> None:
        self.call("Page.navigate", url=url)

    def evaluate(self, expression: str) -> object:
        """The value of a JavaScript expression in the page (promises awaited)."""
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        return result["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 60.0) -> object:
        """Evaluate ``expression`` until it is truthy; its value (``TimeoutError`` after ``timeout`` s)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            value = self.evaluate(expression)
            if value:
                return value
            time.sleep(0.1)
        raise TimeoutError(f"the page never satisfied {expression!r}")

    def click(self, x: float, y: float) -> None:
        for kind in ("mousePressed", "mouseReleased"):
            self.call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)

    def screenshot(self) -> np.ndarray:
        """The page as it is drawn now: RGB (height, width, 3) uint8."""
        from PIL import Image

        data = base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])
        return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))

    def settled(self, timeout: float = 40.0, quiet: float = 1.0) -> np.ndarray:
        """A screenshot once the picture has stopped changing for ``quiet`` seconds (fades, loading)."""
        deadline = time.monotonic() + timeout
        last = self.screenshot()
        still_since = time.monotonic()
        while time.monotonic() < deadline:
            time.sleep(0.3)
            now = self.screenshot()
            if now.shape != last.shape or np.abs(now.astype(int) - last.astype(int)).max() > 3:
                still_since = time.monotonic()
            elif time.monotonic() - still_since >= quiet:
                return now
            last = now
        raise TimeoutError(f"the picture kept changing for {timeout} s")

    def rectangle(self, selector: str) -> tuple[float, float, float, float] | None:
        """``(left, top, width, height)`` of the first element matching ``selector``, or ``None``."""
        value = self.evaluate(
            f"(() => {{ const e = document.querySelector({json.dumps(selector)}); if (!e) return null;"
            " const r = e.getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()"
        )
        return None if value is None else tuple(value)  # type: ignore[arg-type, return-value]

    def dismiss_notifications(self) -> None:
        """Close the notifications viser shows (e.g. that WebGL runs in software here)."""
        self.evaluate("document.querySelectorAll('.mantine-Notification-closeButton').forEach(b => b.click())")


class Playback:
    """viser's playback bar in a written file (a recording with a timeline)."""

    SLIDER = ".mantine-Slider-root"

    def __init__(self, browser: Browser) -> None:
        self.browser = browser

    def wait_loaded(self, timeout: float = 60.0) -> None:
        self.browser.wait_for(f"document.querySelector({json.dumps(self.SLIDER)}) !== null", timeout)
        self.browser.dismiss_notifications()

    def seek(self, fraction: float) -> float:
        """Click the time slider at ``fraction`` of its length (pausing the playback); the time it
        then shows (s), once the click has moved it."""
        left, top, width, height = self.browser.rectangle(self.SLIDER) or (0, 0, 0, 0)
        before = self.time()
        self.browser.click(left + fraction * width, top + height / 2)
        deadline = time.monotonic() + 10
        while self.time() == before and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(0.2)  # (a playing recording may still have been moving it)
        return self.time()

    def time(self) -> float:
        return float(self.browser.evaluate("document.querySelector('[role=slider]').getAttribute('aria-valuenow')"))

    def canvas(self) -> tuple[float, float, float, float]:
        """Where the 3-D view is drawn: ``(left, top, width, height)``."""
        rectangle = self.browser.rectangle("canvas")
        assert rectangle is not None, "no canvas on the page"
        return rectangle


def main() -> None:
    parser = argparse.ArgumentParser(description="Take the picture of a file written by 'ompl-balance show -o'.")
    parser.add_argument("page", type=Path)
    parser.add_argument("picture", type=Path)
    parser.add_argument("--at", type=float, default=0.5, help="where on the time slider (0..1)")
    parser.add_argument("--size", default="960x600", help="window size WIDTHxHEIGHT")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    from PIL import Image

    with Browser(width, height) as browser:
        browser.open(args.page.resolve().as_uri())
        playback = Playback(browser)
        playback.wait_loaded()
        playback.seek(args.at)
        Image.fromarray(browser.settled()).save(args.picture, optimize=True)
    print(args.picture)


if __name__ == "__main__":
    main()
