"""stefan/budget.py: each refusal's one line (soft limits on cell updates, saves and disk; the
free space where the run writes), a given time step, the machine's memory under an
address-space limit, and the size and duration wording."""

from __future__ import annotations

import math
import os
import resource
from pathlib import Path

import pytest

from whitted.stefan import budget
from whitted.stefan.case import CaseError, load_case

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def case():
    return load_case(REPO / "examples" / "stefan" / "hollow_ice.toml")  # a 50³ grid


def _with_time(case, **time):
    return case.model_copy(update={"time": case.time.model_copy(update=time)})


def test_a_given_time_step_is_the_estimates(case):
    e = budget.estimate(_with_time(case, dt=0.05))
    assert e.dt == 0.05 and e.steps == 72_000  # 3600 s / 0.05 s
    assert e.cell_updates == 125_000 * 72_000
    assert e.seconds == pytest.approx(125_000 * 72_000 / 50e6)


def test_too_many_cell_updates(case):
    # 1e7 steps (under the steps' limit); the key is the given time step
    long = _with_time(case, end=1e7 * 0.05, dt=0.05)
    with pytest.raises(CaseError) as caught:
        budget.check(long, file="c.toml")
    # 1e7 steps x 125,000 cells = 1.25e12 cell updates, 25,000 s at 50 M/s
    assert str(caught.value) == (
        "c.toml: time.dt: 1e+07 steps on 125,000 cells is 1.25e+12 cell updates (about "
        "6.94 h), over the limit of 1e+12 (--allow-large to go beyond)")
    assert budget.check(long, allow_large=True).steps == 10**7


def test_too_many_saves_and_too_much_disk(case):
    with pytest.raises(CaseError) as caught:
        budget.check(_with_time(case, save_every=0.03), file="c.toml")
    assert str(caught.value) == ("c.toml: time.save_every: 120,001 saved times is over the "
                                 "limit of 100,000 (--allow-large to go beyond)")
    # 20,001 saves x (25 B x 125,000 cells + 16 kB) = 62.8e9 B = 58.5 GiB, over 50 GiB
    with pytest.raises(CaseError) as caught:
        budget.check(_with_time(case, save_every=0.18), file="c.toml")
    assert str(caught.value) == ("c.toml: time.save_every: 20,001 saved times write about "
                                 "58.5 GB, over the limit of 50 GB (--allow-large to go "
                                 "beyond)")


def test_the_free_space_where_the_run_writes(case, tmp_path, monkeypatch):
    monkeypatch.setattr(budget, "free_disk", lambda where: 1000)
    with pytest.raises(CaseError) as caught:
        budget.check(case, tmp_path / "out", file="c.toml")
    # 31 saves x (25 B x 125,000 + 16 kB) = 97.4e6 B = 92.9 MiB; a resumed run with every save
    # needs none
    assert str(caught.value) == (f"c.toml: time.save_every: 31 saved times write about "
                                 f"92.9 MB; {tmp_path / 'out'} has 0.977 kB free")
    assert budget.check(case, tmp_path / "out", existing_saves=31).saves == 31


def test_free_disk_looks_at_the_nearest_existing_folder(tmp_path, monkeypatch):
    seen = []

    class Usage:
        free = 12345

    def usage(place):
        seen.append(place)
        return Usage

    monkeypatch.setattr(budget.shutil, "disk_usage", usage)
    assert budget.free_disk(tmp_path / "a" / "b" / "c") == 12345
    assert seen == [tmp_path]

    def broken(place):
        raise OSError("no file system")

    monkeypatch.setattr(budget.shutil, "disk_usage", broken)
    assert budget.free_disk(tmp_path) is None


def test_machine_memory_under_an_address_space_limit(monkeypatch):
    physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    monkeypatch.setattr(resource, "getrlimit", lambda which: (2**20, resource.RLIM_INFINITY))
    assert budget.machine_memory() == min(2**20, physical)

    def no_sysconf(name):
        raise ValueError(name)

    monkeypatch.setattr(os, "sysconf", no_sysconf)
    assert budget.machine_memory() == 2**20
    monkeypatch.setattr(resource, "getrlimit",
                        lambda which: (resource.RLIM_INFINITY, resource.RLIM_INFINITY))
    assert budget.machine_memory() is None


def test_sizes_and_durations_in_words():
    assert budget._size(3 * 2**40) == "3 TB"
    assert budget._size(1.5 * 2**30) == "1.5 GB"
    assert budget._size(2**20) == "1 MB"
    assert budget._size(1536) == "1.5 kB"
    assert budget._hours(5400) == "1.5 h"
    assert budget._hours(90) == "1.5 min"
    assert math.isclose(budget.CELL_UPDATES_PER_SECOND, 50e6)
