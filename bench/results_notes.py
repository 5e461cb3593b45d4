"""Writing a bench's generated results fragment without losing the notes written by hand.

A results file (``bench/*_results.md``) is rewritten by its bench on every run; the paragraphs
that sessions add below the generated part start with a line ``Notes (...`` and run to the end
of the file. :func:`write_keeping_notes` puts them back below the new run, so a rerun updates
the numbers and keeps the history of what was measured and why.
"""
from __future__ import annotations

import os
from pathlib import Path

NOTES_MARK = "Notes ("


def hand_notes(text):
    """The hand-written tail of a results fragment: from its first line that starts with
    NOTES_MARK to the end ("" when there is none)."""
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.startswith(NOTES_MARK):
            return "\n".join(lines[i:]).rstrip() + "\n"
    return ""


def write_keeping_notes(path, generated):
    """Write ``generated`` to ``path`` (atomically: a temporary name, then rename) followed by
    the hand-written notes of the file it replaces."""
    path = Path(path)
    old = path.read_text() if path.is_file() else ""
    notes = hand_notes(old)
    text = generated.rstrip() + "\n" + ("\n" + notes if notes else "")
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)
