"""mkdocs hooks (mkdocs.yml ``hooks:``): the generated parts of the pages.

A page holds a marker line ``<!-- mpipd:NAME -->`` where a generated part goes;
:func:`on_page_markdown` replaces it with :data:`GENERATORS`' text, read from the
code and the committed files at build time, so the site cannot drift from them.
An unknown marker, or a generator that fails, fails the build.

* ``scene-reference``: every scene key (docs/gen_scene_reference.py);
* ``validation-summary``: the Summary section of studies/validation/record.md
  (written by ``python -m mpipd.post validate``);
* ``validation-targets``: the judged quantities and their ranges
  (``mpipd.post.targets.TARGETS``);
* ``bench-table``: the throughput table of the newest committed ``make bench`` log,
  studies/bench_logs/make_bench_<commit>.log (``benchmarks/bench_table.py``).
"""
from __future__ import annotations

import importlib.util
import re
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
for p in (str(ROOT), str(HERE)):        # mkdocs restores sys.path after loading a hook:
    if p not in sys.path:               # import what the generators need now
        sys.path.insert(0, p)

import gen_scene_reference  # noqa: E402

MARKER = re.compile(r"^<!-- mpipd:([\w-]+) -->$", re.M)
RECORD = ROOT / "studies" / "validation" / "record.md"
BENCH_LOGS = ROOT / "studies" / "bench_logs"


def scene_reference() -> str:
    return gen_scene_reference.render()


def section(text: str, title: str) -> str:
    """The body of the ``## title`` section of a Markdown text (to the next ``## ``)."""
    m = re.search(rf"^## {re.escape(title)}\s*$(.*?)(?=^## |\Z)", text, re.M | re.S)
    if m is None:
        raise ValueError(f"no section '## {title}'")
    return m.group(1).strip()


def validation_summary() -> str:
    return section(RECORD.read_text(encoding="utf-8"), "Summary")


def validation_targets() -> str:
    from mpipd.post.targets import TARGETS
    rows = ["| quantity | unit | paper | experiment | range used |", "|---|---|---|---|---|"]
    for t in TARGETS:
        if t.kind == "information":
            continue
        cells = (t.label, t.unit, t.paper, t.experiment, t.band)
        rows.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(rows)


def newest_bench_log() -> Path:
    """The committed ``make bench`` log of the most recent commit (by commit time of
    the commit in its name; without git, by the file's modification time)."""
    logs = sorted(BENCH_LOGS.glob("make_bench_*.log"))
    if not logs:
        raise FileNotFoundError(f"no make_bench_*.log in {BENCH_LOGS}")

    def when(log: Path) -> float:
        commit = log.stem.removeprefix("make_bench_")
        try:
            out = subprocess.run(["git", "-C", str(ROOT), "log", "-1", "--format=%ct", commit],
                                 capture_output=True, text=True, timeout=10)
            if out.returncode == 0 and out.stdout.strip():
                return float(out.stdout.strip())
        except OSError:
            pass
        return log.stat().st_mtime
    return max(logs, key=when)


def bench_table() -> str:
    log = newest_bench_log()
    spec = importlib.util.spec_from_file_location("bench_table", ROOT / "benchmarks" / "bench_table.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    runs, peer = mod.parse(log.read_text(encoding="utf-8"))
    rel = log.relative_to(ROOT).as_posix()
    return (f"From `{rel}` (the newest committed log), by "
            f"`python benchmarks/bench_table.py {rel}`:\n\n" + "\n".join(mod.table(runs, peer)))


GENERATORS = {"scene-reference": scene_reference, "validation-summary": validation_summary,
              "validation-targets": validation_targets, "bench-table": bench_table}


def expand(markdown: str) -> str:
    """Every marker of a page replaced by its generated text."""
    def one(m):
        name = m.group(1)
        if name not in GENERATORS:
            raise KeyError(f"unknown docs marker <!-- mpipd:{name} --> "
                           f"(known: {', '.join(GENERATORS)})")
        return GENERATORS[name]()
    return MARKER.sub(one, markdown)


def on_page_markdown(markdown, page, config, files):
    return expand(markdown)


#: a Sphinx role left in a docstring's HTML (mkdocstrings renders ``:class:`X``` as
#: ":class:<code>X</code>"): the role's name and a leading "~" go
ROLE_HTML = re.compile(r":(?:class|func|meth|mod|data|attr|obj):(<code>)~?")
#: reST's "::" before a literal block, at the end of a docstring's paragraph
LITERAL_MARK = re.compile(r"::(</p>)")


def on_page_content(html, page, config, files):
    return LITERAL_MARK.sub(r":\1", ROLE_HTML.sub(r"\1", html))
