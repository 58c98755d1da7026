"""What users read (program output, help texts, messages, the source and its comments, the
README, docs/, the example and bench scenes that ship with whitted) speaks of whitted, never
of how its development was organised: no issue numbers, defects, tickets or sessions."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

HISTORY = re.compile(
    r"\bissue\b|\bissues\b|\bdefect\s*#?\d|\bticket\b|\bwork history\b"
    r"|\bthis session\b|\bthe brief\b",
    re.IGNORECASE,
)


def user_facing_files() -> list[Path]:
    files = sorted((ROOT / "src" / "whitted").rglob("*.py"))
    files += [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    files += sorted((ROOT / "examples").rglob("*.toml"))
    files += sorted((ROOT / "examples").rglob("*.md"))
    files += sorted((ROOT / "benchmarks").glob("*.toml"))
    return files


def test_the_pattern_catches_what_it_should():
    for text in ("see issue 30", "the issue's numbers", "(defect 8)", "ticket 4", "this session"):
        assert HISTORY.search(text), text
    for text in ("a tissue", "issued", "colour #ff8800", "the session's widget"):
        assert not HISTORY.search(text), text


def test_no_development_history_in_what_users_read():
    found = []
    for path in user_facing_files():
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if HISTORY.search(line):
                found.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert len(user_facing_files()) > 100
    assert not found, "\n".join(found)
