"""The farm's task loop (farm/watch.py run_tasks) on a made-up client: what it does when the
scheduler's connection goes mid-job, or a result has to go again with no ready worker."""

from __future__ import annotations

import pytest

pytest.importorskip("distributed")

from whitted.farm import ClusterLost  # noqa: E402
from whitted.farm.watch import run_tasks  # noqa: E402


class Future:
    def __init__(self, name: str, status: str = "finished") -> None:
        self.key = name
        self.status = status


class Watch:
    """What run_tasks asks of its watch: every task done at once."""

    def __init__(self, status: str) -> None:
        self.client = type("Client", (), {"status": status,
                                          "scheduler": type("S", (), {"address": "tcp://h:1"}),
                                          "scheduler_info": lambda self, **kw: {}})()
        self.result_seconds = 30.0

    def wait(self, futures):
        return set(futures)

    def disconnected(self) -> bool:
        return self.client.status not in ("running", "newly-created")

    def lost(self, exc=None):
        return ClusterLost(f"lost the connection to the scheduler at tcp://h:1 ({exc})")

    def give_up_on(self, future):
        return []

    def ready_workers(self, info):
        return []

    def check(self, keys):
        return [], set()


def failing(exc: BaseException):
    def on_done(future, item):
        raise exc
    return on_done


def test_a_closed_connection_pool_after_the_scheduler_went_is_cluster_lost():
    watch = Watch("closed")
    with pytest.raises(ClusterLost, match=r"^lost the connection to the scheduler at "
                                          r"tcp://h:1 \(ConnectionPool is closed\)$"):
        run_tasks(watch, {Future("a"): 0}, lambda item, workers: Future("b"),
                  failing(RuntimeError("ConnectionPool is closed")))


def test_a_runtime_error_while_connected_is_not_hidden():
    watch = Watch("running")
    with pytest.raises(RuntimeError, match="a defect"):
        run_tasks(watch, {Future("a"): 0}, lambda item, workers: Future("b"),
                  failing(RuntimeError("a defect")))


def test_a_result_to_run_again_with_no_ready_worker_goes_to_any_worker():
    """Its worker did not hand it over (TimeoutError) and no worker is ready now: it is
    submitted with no worker restriction (None), not given up on."""
    watch = Watch("running")
    submitted = []
    calls = []

    def on_done(future, item):
        calls.append(future.key)
        if future.key == "a":
            raise TimeoutError

    def submit(item, workers):
        submitted.append((item, workers))
        return Future("again")

    assert run_tasks(watch, {Future("a"): 7}, submit, on_done) is True
    assert submitted == [(7, None)] and calls == ["a", "again"]


class ClosedClient:
    """A Dask client the scheduler's loss has closed: it has no scheduler left to ask, and
    its questions fail with AttributeError ('NoneType' object has no attribute ...)."""

    status = "running"  # not yet updated: the race the watch must survive
    scheduler = None

    def get_events(self, topic):
        return []

    def subscribe_topic(self, topic, handler):
        pass

    def _gone(self, *args, **kwargs):
        return None.processing  # what Dask's client does with no scheduler

    scheduler_info = processing = who_has = _gone


class WaitingFuture:
    key = "frame-0"

    def result(self, timeout=None):
        raise TimeoutError


def test_a_client_closed_by_the_scheduler_s_loss_is_cluster_lost():
    from whitted.farm.watch import Watch as ClusterWatch

    watch = ClusterWatch(ClosedClient(), stall_floor=5.0)
    with pytest.raises(ClusterLost, match="^lost the connection to the scheduler at "
                                          "the scheduler$"):
        watch.check({"frame-0"})
    with pytest.raises(ClusterLost):
        watch.result(WaitingFuture())
    assert watch.give_up_on(WaitingFuture()) == []


def test_an_attribute_error_of_a_connected_client_is_not_hidden():
    from whitted.farm.watch import Watch as ClusterWatch

    client = ClosedClient()
    client.scheduler = type("S", (), {"address": "tcp://h:1"})()
    watch = ClusterWatch(client, stall_floor=5.0)
    with pytest.raises(AttributeError):
        watch.check({"frame-0"})


def test_a_slow_answer_of_the_scheduler_is_a_timeout_not_a_lost_cluster():
    """A question that times out (TimeoutError is an OSError) stays a timeout: the task
    loop then gives up on that result and submits the task again, instead of ending the
    whole render as if the scheduler were gone; a broken connection is a lost cluster."""
    from whitted.farm.watch import Watch as ClusterWatch

    def slow(*args, **kwargs):
        raise TimeoutError

    def broken(*args, **kwargs):
        raise ConnectionResetError("reset by peer")

    watch = ClusterWatch(ClosedClient(), stall_floor=5.0)
    with pytest.raises(TimeoutError):
        watch.ask(slow, [WaitingFuture()])
    with pytest.raises(ClusterLost):
        watch.ask(broken)
