"""The markdown tables the study scripts of benchmarks/ print (class_rules.py,
family_factor.py, ring_factors.py): printed, and written to ``out`` if given."""
from __future__ import annotations

from pathlib import Path


def emit(lines: list[str], out: str | None) -> str:
    """Join ``lines``, print them, write them to ``out`` (if not None); the text."""
    text = "\n".join(lines) + "\n"
    print(text)
    if out:
        Path(out).write_text(text)
    return text
