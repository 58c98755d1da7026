"""Every command's ``--help`` reads well in an 80-column terminal: nothing wider, and no
paragraph of its description broken early (a line cut short in mid-sentence)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

COMMANDS = [[], ["render"], ["export"], ["info"], ["animate"], ["sweep"], ["bench"],
            ["stefan"]]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c) or "whitted")
def test_help_at_80_columns(command):
    env = {**os.environ, "COLUMNS": "80", "TERM": "dumb", "NO_COLOR": "1"}
    env.pop("FORCE_COLOR", None)
    run = subprocess.run([sys.executable, "-m", "whitted", *command, "--help"], env=env,
                         capture_output=True, text=True, timeout=120, check=True)
    lines = run.stdout.splitlines()
    assert all(len(line) <= 80 for line in lines), max(lines, key=len)
    # the description: the text between the usage line and the first box
    first_box = next(i for i, line in enumerate(lines) if line.lstrip().startswith("╭"))
    text = [line.strip() for line in lines[1:first_box]]
    paragraphs: list[list[str]] = [[]]
    for line in text:
        if line:
            paragraphs[-1].append(line)
        elif paragraphs[-1]:
            paragraphs.append([])
    for paragraph in paragraphs:
        for line in paragraph[:-1]:  # every line but a paragraph's last fills the width
            assert len(line) >= 60, (line, paragraph)


@pytest.mark.parametrize("command", [[], ["stefan"]], ids=lambda c: " ".join(c) or "whitted")
def test_command_list_summaries_are_whole_lines(command):
    """The list of commands shows one sentence a command, wrapped to the column: no row but
    an entry's last cut short (a docstring's own line break kept in mid-sentence)."""
    env = {**os.environ, "COLUMNS": "80", "TERM": "dumb", "NO_COLOR": "1"}
    env.pop("FORCE_COLOR", None)
    run = subprocess.run([sys.executable, "-m", "whitted", *command, "--help"], env=env,
                         capture_output=True, text=True, timeout=120, check=True)
    lines = run.stdout.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("╭─ Commands"))
    end = next(i for i in range(start, len(lines)) if lines[i].startswith("╰"))
    rows = [line[1:-1] for line in lines[start + 1:end]]
    column = len(rows[0]) - len(rows[0][1:].split(" ", 1)[1].lstrip()) - 1
    width = len(rows[0]) - column - 1
    entries: list[list[str]] = []
    for row in rows:
        if row[1] != " ":
            entries.append([])
        entries[-1].append(row[column:].rstrip())
    assert len(entries) >= 4, rows
    for entry in entries:
        assert all(len(row) >= 0.6 * width for row in entry[:-1]), entry
        assert entry[-1].endswith("."), entry  # one whole sentence
