"""Stopping a render in a real Jupyter kernel (ipykernel, driven by jupyter_client as a
frontend drives it): the kernel's interrupt stops ``whitted.render`` and the picture so far
comes back; the Stop button of an awaited ``whitted.render_async`` is heard while it renders
(a frontend's click is a comm message to the button)."""

from __future__ import annotations

import importlib.util
import queue
import time

import pytest

jupyter_client = pytest.importorskip("jupyter_client")
if importlib.util.find_spec("ipykernel") is None:  # the kernel runs in its own process;
    pytest.skip("ipykernel is not installed", allow_module_level=True)  # not imported here
pytest.importorskip("ipywidgets")

SETUP = """
import whitted
scene = whitted.default_scene().with_settings(width=640, height=480, threads=1,
                                              shadow_samples=16, samples=16)
whitted.render(scene, width=16, height=12)   # kernels loaded before the clock matters
"""


@pytest.fixture(scope="module")
def kernel():
    km, kc = jupyter_client.manager.start_new_kernel(kernel_name="python3",
                                                     startup_timeout=180)
    try:
        _run(kc, SETUP, timeout=600)
        yield km, kc
    finally:
        kc.stop_channels()
        km.shutdown_kernel(now=True)


def _run(kc, code: str, *, timeout: float = 120, on_message=None) -> list[dict]:
    """Execute ``code``; every IOPub message of it until the kernel is idle again."""
    msg_id = kc.execute(code)
    messages = []
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            msg = kc.get_iopub_msg(timeout=1)
        except queue.Empty:
            continue
        if msg["parent_header"].get("msg_id") != msg_id:
            continue
        messages.append(msg)
        if on_message is not None:
            on_message(msg)
        if msg["msg_type"] == "error":
            raise AssertionError("\n".join(msg["content"]["traceback"]))
        if msg["msg_type"] == "status" and msg["content"]["execution_state"] == "idle":
            return messages
    raise AssertionError(f"no answer in {timeout} s")


def _printed(messages) -> str:
    return "".join(m["content"]["text"] for m in messages if m["msg_type"] == "stream")


def test_kernel_interrupt_keeps_the_picture_so_far(kernel):
    km, kc = kernel
    sent, rendering = [], []

    def interrupt_when_rendering(msg):
        # the bar's updates (one trait a message): "rendering", then a value past 0
        data = msg["content"].get("data", {})
        state = data.get("state", {}) if isinstance(data, dict) else {}
        if state.get("description") == "rendering":
            rendering.append(1)
        if rendering and not sent and state.get("value", 0) > 0:
            sent.append(1)
            km.interrupt_kernel()

    messages = _run(kc, "image = whitted.render(scene)\n"
                        "s = image.meta['stats']\n"
                        "print(s.cancelled, s.tiles_done, s.tiles_total)",
                    on_message=interrupt_when_rendering)
    assert sent
    cancelled, done, total = _printed(messages).split()
    assert cancelled == "True" and 0 < int(done) < int(total)


def test_stop_button_of_an_awaited_render_is_heard(kernel):
    _, kc = kernel
    button, clicked, rendering = [], [], []

    def click_stop(msg):
        # the Stop button appears with the view; it is clicked once the bar shows tiles done
        data = msg["content"].get("data", {})
        state = data.get("state", {}) if isinstance(data, dict) else {}
        if msg["msg_type"] == "comm_open" and state.get("_model_name") == "ButtonModel" \
                and state.get("description") == "Stop":
            button.append(msg["content"]["comm_id"])
        if state.get("description") == "rendering":
            rendering.append(1)
        if button and rendering and not clicked and state.get("value", 0) > 0:
            clicked.append(1)
            click = kc.session.msg("comm_msg", {
                "comm_id": button[0],
                "data": {"method": "custom", "content": {"event": "click"}}})
            kc.shell_channel.send(click)

    messages = _run(kc, "image = await whitted.render_async(scene)\n"
                        "s = image.meta['stats']\n"
                        "print(s.cancelled, s.tiles_done, s.tiles_total)",
                    on_message=click_stop)
    assert clicked
    cancelled, done, total = _printed(messages).split()
    assert cancelled == "True" and int(done) < int(total)
