"""A screenshot of a recording in Rerun's web viewer, headless: serves the
.rrd with the rerun CLI that rerun-sdk installs, opens the viewer in
headless Chromium (Debian's ``chromium-headless-shell``, WebGL on
SwiftShader) over the DevTools protocol, waits, and saves a PNG.

    python viz_screenshot.py recording.rrd out.png [seconds]

Needs ``pip install 'kinplan[viz]' tornado`` (tornado for the DevTools
websocket) and ``apt-get install chromium-headless-shell``.
"""
import asyncio
import base64
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import urllib.parse
import urllib.request
from typing import Any, Dict

from tornado.websocket import websocket_connect


def rerun_binary() -> str:
    import importlib

    path = os.path.join(os.path.dirname(importlib.import_module("rerun_cli").__file__ or ""), "rerun")
    return path if os.path.exists(path) else (shutil.which("rerun") or "rerun")


async def capture(page: str, out: str, wait: float, port: int) -> None:
    for _ in range(100):
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/json") as r:
                targets = json.load(r)
            break
        except OSError:
            time.sleep(0.1)
    ws = await websocket_connect([t for t in targets if t["type"] == "page"][0]["webSocketDebuggerUrl"],
                                 max_message_size=1 << 28)
    counter = 0

    async def call(method: str, **params: Any) -> Dict[str, Any]:
        nonlocal counter
        counter += 1
        await ws.write_message(json.dumps({"id": counter, "method": method, "params": params}))
        while True:
            message = await ws.read_message()
            if message is None:
                raise RuntimeError("the browser closed the connection")
            reply: Dict[str, Any] = json.loads(message)
            if reply.get("id") == counter:
                return reply

    await call("Emulation.setDeviceMetricsOverride", width=1600, height=1000, deviceScaleFactor=1, mobile=False)
    await call("Page.navigate", url=page)
    await asyncio.sleep(wait)  # the wasm viewer loads, then streams the recording
    shot = await call("Page.captureScreenshot", format="png")
    with open(out, "wb") as f:
        f.write(base64.b64decode(shot["result"]["data"]))


def main() -> None:
    rrd, out = sys.argv[1], sys.argv[2]
    wait = float(sys.argv[3]) if len(sys.argv) > 3 else 40.0
    web, grpc, devtools = 9190, 9977, 9333
    viewer = subprocess.Popen([rerun_binary(), "--serve-web", "--web-viewer-port", str(web), "--port", str(grpc),
                               "--renderer", "webgl", "--hide-welcome-screen", rrd],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    browser = subprocess.Popen(["chromium-headless-shell", "--no-sandbox", "--use-angle=swiftshader",
                                "--enable-unsafe-swiftshader", "--window-size=1600,1000",
                                f"--remote-debugging-port={devtools}", "about:blank"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        time.sleep(2)
        source = urllib.parse.quote(f"rerun+http://localhost:{grpc}/proxy", safe="")
        asyncio.run(capture(f"http://127.0.0.1:{web}/?url={source}&renderer=webgl", out, wait, devtools))
        print("wrote", out)
    finally:
        for p in (browser, viewer):  # each in a session of its own: the launcher's children go too
            os.killpg(p.pid, signal.SIGTERM)
            p.wait()


if __name__ == "__main__":
    main()
