"""The Markdown report of a demo run (and of a second run in another scene, added to it)."""

from __future__ import annotations

import os
from collections.abc import Sequence

import yaml

from thesis_demos.analysis import Verdict
from thesis_demos.scenarios import Scenario

__all__ = ["markdown"]


def _sections(results: Sequence[tuple[Scenario, Verdict, str]]) -> list[dict]:
    return [{"name": s.name, "title": s.title, "passed": bool(v.passed), "summary": v.summary,
             "figures": {k: float(x) for k, x in v.figures.items()}, "png": png} for s, v, png in results]


def markdown(robot: str, results: Sequence[tuple[Scenario, Verdict, str]], seconds: float, data: str = "",
             append: bool = False) -> str:
    """A short report: one section per demonstration with its verdict, figures and plot.

    `data`: a YAML file keeping the sections and the time; with `append`, the sections it holds come first
    (a run before this one, in the same output folder) and the time adds up.
    """
    sections = _sections(results)
    if append and data and os.path.isfile(data):
        with open(data, encoding="utf-8") as handle:
            before = yaml.safe_load(handle) or {}
        sections = list(before.get("sections", [])) + sections
        seconds += float(before.get("seconds", 0.0))
    if data:
        with open(data, "w", encoding="utf-8") as handle:
            kept = {"robot": robot, "seconds": seconds, "sections": sections}
            yaml.safe_dump(kept, handle, sort_keys=False)
    passed = sum(s["passed"] for s in sections)
    lines = [
        f"# Thesis demonstrations on the simulated {robot}",
        "",
        f"{passed} of {len(sections)} passed, in {seconds:.0f} s of wall time.",
        "",
    ]
    for s in sections:
        lines += [
            f"## {s['title']}: {'PASS' if s['passed'] else 'FAIL'}",
            "",
            s["summary"] + ".",
            "",
            "| figure | value |",
            "|---|---|",
            *(f"| {name} | {value:.4g} |" for name, value in s["figures"].items()),
            "",
            *([f"![{s['name']}]({s['png']})", ""] if s["png"] else []),
        ]
    return "\n".join(lines)
