"""Farm pieces that need no cluster: the probe plugin's setup in a worker (Ctrl-C ignored, a
worker without whitted named in an event), the scheduler address check and the dashboard
link."""

from __future__ import annotations

import signal
import socket
import sys
import threading

import pytest

from whitted.farm import cluster, probe
from whitted.farm.errors import ClusterLost, FarmError


class FakeWorker:
    address = "tcp://10.0.0.7:40001"
    name = 3

    def __init__(self):
        self.events = []

    def log_event(self, topic, msg):
        self.events.append((topic, msg))


@pytest.fixture
def sigint():
    """Python's own Ctrl-C handler for the test (whatever this process inherited: a job
    started in the background of a shell gets SIGINT ignored), the one before restored."""
    before = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def test_the_probe_makes_a_worker_ignore_ctrl_c(sigint):
    worker = FakeWorker()
    probe.WhittedProbe(quiet_interrupt=True).setup(worker)
    assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    assert worker.events == []  # whitted imports here: nothing to say


def test_only_the_main_thread_can_ignore_ctrl_c(sigint):
    result = []
    thread = threading.Thread(target=lambda: result.append(probe.ignore_interrupt()))
    thread.start()
    thread.join()
    assert result == [False]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_worker_that_cannot_import_whitted_says_so(monkeypatch):
    monkeypatch.setitem(sys.modules, "whitted.farm.worker", None)
    worker = FakeWorker()
    probe.WhittedProbe().setup(worker)
    assert worker.events == [(probe.EVENT_TOPIC, {
        "worker": "tcp://10.0.0.7:40001", "name": "3", "status": "missing",
        "error": "ModuleNotFoundError: import of whitted.farm.worker halted; None in "
                 "sys.modules",
        "python": sys.executable})]


@pytest.mark.parametrize("address", ["http://example.org:80", "tcp://:8786", "tcp://host",
                                     "tcp://host:99999"])
def test_a_scheduler_address_that_is_not_tcp_host_port(address):
    with pytest.raises(FarmError) as caught:
        cluster.reach_scheduler(address)
    assert str(caught.value) == f"--scheduler {address}: not an address tcp://HOST:PORT"


def test_a_scheduler_that_refuses_and_one_that_does_not_answer(monkeypatch):
    with socket.socket() as s:  # a port nobody listens on: bound, never listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        with pytest.raises(ClusterLost) as caught:
            cluster.reach_scheduler(f"127.0.0.1:{port}")
    assert str(caught.value) == (f"--scheduler 127.0.0.1:{port}: cannot reach the scheduler "
                                 "(Connection refused)")

    def silent(address, timeout):
        raise TimeoutError

    monkeypatch.setattr(cluster.socket, "create_connection", silent)
    with pytest.raises(ClusterLost) as caught:
        cluster.reach_scheduler("tcp://10.0.0.7:8786", timeout=2.0)
    assert str(caught.value) == ("--scheduler tcp://10.0.0.7:8786: no answer in 2 s (is a "
                                 "scheduler running there, and the port open?)")


def test_a_reachable_scheduler_passes(monkeypatch):
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen()
        cluster.reach_scheduler(f"tcp://127.0.0.1:{server.getsockname()[1]}")  # no error


class FakeClient:
    dashboard_link = "http://127.0.0.1:8787/status"

    def __init__(self, info=None, error=None):
        self.info, self.error = info, error

    def scheduler_info(self):
        if self.error:
            raise self.error
        return self.info


def test_the_dashboard_link(monkeypatch):
    monkeypatch.setattr(cluster, "has_dashboard", lambda: False)
    assert cluster.dashboard_link(FakeClient({"services": {"dashboard": 8787}})) is None
    monkeypatch.setattr(cluster, "has_dashboard", lambda: True)
    assert cluster.dashboard_link(FakeClient({"services": {"dashboard": 8787}})) == \
        "http://127.0.0.1:8787/status"
    assert cluster.dashboard_link(FakeClient({"services": {}})) is None
    assert cluster.dashboard_link(FakeClient(error=OSError("gone"))) is None
