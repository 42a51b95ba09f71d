"""Headless Chromium driven over the DevTools protocol, for the browser tests of the course.

Chromium starts with a debugging port of its own choosing (read back from its profile), on 127.0.0.1, and stops with
:meth:`Browser.close`. The tests drive JupyterLab through its own command registry (``window.jupyterapp``, exposed
by the server option ``LabApp.expose_app_in_browser``) and through real DOM clicks on widgets; the websocket client
is jupyter_server's own dependency.
"""

from __future__ import annotations

import base64
import itertools
import json
import os
import shutil
import subprocess
import time
import urllib.request
from pathlib import Path
from typing import Any, NoReturn

import pytest
import websocket

#: Debian's headless browser, or None where it is not installed.
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
#: How long a wait may last before it is taken for a hang [s]. The tests bound the work they ask of the browser
#: (pages, frames, cells), never the time it takes: this only ends a wait that would never end, on any machine.
HANG_GUARD = 900.0


def unavailable(reason: str) -> NoReturn:
    """Skip a browser test for ``reason``; in CI (``RRBOT_WORKSHOP_REQUIRE_BROWSER=1``, set by ``.ci/run``) the browser
    tests may not skip, so the same reason fails it."""
    if os.environ.get("RRBOT_WORKSHOP_REQUIRE_BROWSER") == "1":
        pytest.fail(f"{reason} (RRBOT_WORKSHOP_REQUIRE_BROWSER=1: the browser tests may not skip)", pytrace=False)
    pytest.skip(reason)


class Browser:
    """One headless Chromium with one page.

    Args:
        chromium: Path of the Chromium executable.
        profile: A fresh directory for its profile.
        size: Window size in pixels.
        webgl: Render WebGL in software (SwiftShader), for pages that draw a 3D scene.
    """

    def __init__(self, chromium: str, profile: Path, size: tuple[int, int] = (1400, 900), webgl: bool = False) -> None:
        profile.mkdir(parents=True, exist_ok=True)
        (profile / "DevToolsActivePort").unlink(missing_ok=True)  # a reused profile must not hand us an old port
        self._process = subprocess.Popen(
            [chromium, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-sync",
             "--disable-background-networking", "--remote-debugging-address=127.0.0.1", "--remote-debugging-port=0",
             f"--user-data-dir={profile}", f"--window-size={size[0]},{size[1]}",
             *(["--enable-unsafe-swiftshader"] if webgl else []), "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port_file = profile / "DevToolsActivePort"
        deadline = time.monotonic() + HANG_GUARD
        while not (port_file.exists() and port_file.read_text().strip()):
            if self._process.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError("Chromium ended or hung before it opened its debugging port")
            time.sleep(0.1)
        port = int(port_file.read_text().split()[0])
        targets = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json", timeout=10))
        page = next(t for t in targets if t["type"] == "page")
        self._ws = websocket.create_connection(page["webSocketDebuggerUrl"], suppress_origin=True,
                                              timeout=HANG_GUARD)
        self._ids = itertools.count(1)

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        """One DevTools command; its result."""
        request_id = next(self._ids)
        self._ws.send(json.dumps({"id": request_id, "method": method, "params": params}))
        while True:
            message = json.loads(self._ws.recv())
            if message.get("id") == request_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return dict(message["result"])

    def js(self, expression: str) -> Any:
        """Evaluate ``expression`` in the page (promises awaited); its value."""
        result = self.call("Runtime.evaluate", expression=expression, awaitPromise=True, returnByValue=True)
        if "exceptionDetails" in result:
            details = result["exceptionDetails"]
            raise RuntimeError(f"in the page: {details.get('exception', {}).get('description') or details}")
        return result["result"].get("value")

    def wait_for(self, expression: str, *, timeout: float = HANG_GUARD, what: str = "") -> Any:
        """Evaluate ``expression`` until it is truthy; its value.

        Raises:
            AssertionError: After ``timeout`` seconds (a hang guard, not a speed requirement), naming ``what``.
        """
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            value = self.js(expression)
            if value:
                return value
            time.sleep(0.25)
        raise AssertionError(f"timed out after {timeout:g} s waiting for {what or expression}")

    def open(self, url: str) -> None:
        """Navigate and wait for the document to load."""
        self.call("Page.navigate", url=url)
        self.wait_for("document.readyState === 'complete'", what=f"{url} to load")

    def frames(self, count: int) -> None:
        """Wait until the page has drawn ``count`` more animation frames (work done, whatever time it takes)."""
        self.js(f"new Promise(done => {{ let n = 0; const step = () => (++n >= {int(count)} ? done(n) : "
                "requestAnimationFrame(step)); requestAnimationFrame(step); })")

    def viewport(self, width: int, height: int) -> None:
        """Make the page's viewport exactly ``width`` x ``height`` pixels (the window also holds the browser's own bars)."""
        self.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)

    def screenshot(self, path: Path) -> Path:
        """Save a PNG of the page."""
        path.write_bytes(base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"]))
        return path

    def close(self) -> None:
        """Stop Chromium."""
        try:
            self._ws.close()
        except AttributeError:
            pass
        self._process.terminate()
        try:
            self._process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._process.kill()


#: JupyterLab helpers installed in the page: open a notebook and wait for its kernel; run cells; read outputs.
LAB_HELPERS = r"""
window.rrbotTest = {
  async open(path) {
    const app = window.jupyterapp;
    await app.restored;
    const panel = await app.commands.execute('docmanager:open', {path, factory: 'Notebook'});
    await panel.context.ready;
    await panel.sessionContext.ready;
    window.rrbotTest.panel = panel;
    return panel.content.widgets.length;
  },
  async run(indices) {
    const panel = window.rrbotTest.panel, app = window.jupyterapp;
    for (const i of indices) {
      panel.content.activeCellIndex = i;
      await app.commands.execute('notebook:run-cell');
    }
    return true;
  },
  done(indices) {
    const panel = window.rrbotTest.panel;
    const kernel = panel.sessionContext.session && panel.sessionContext.session.kernel;
    return !!kernel && kernel.status === 'idle' &&
      indices.every(i => panel.content.widgets[i].model.executionCount !== null);
  },
  outputText(i) {
    return window.rrbotTest.panel.content.widgets[i].node.querySelector('.jp-Cell-outputArea').innerText;
  },
  errors() {
    return [...window.rrbotTest.panel.node.querySelectorAll('.jp-RenderedText[data-mime-type="application/vnd.jupyter.stderr"]')]
      .map(n => n.innerText).filter(t => /Traceback|Error/.test(t));
  },
};
true
"""
