"""The Markdown report of a demo run."""

from __future__ import annotations

from collections.abc import Sequence

from thesis_demos.analysis import Verdict
from thesis_demos.scenarios import Scenario

__all__ = ["markdown"]


def markdown(robot: str, results: Sequence[tuple[Scenario, Verdict, str]], seconds: float) -> str:
    """A short report: one section per demonstration with its verdict, figures and plot."""
    passed = sum(v.passed for _, v, _ in results)
    lines = [
        f"# Thesis demonstrations on the simulated {robot}",
        "",
        f"{passed} of {len(results)} passed, in {seconds:.0f} s of wall time.",
        "",
    ]
    for scenario, verdict, png in results:
        lines += [
            f"## {scenario.title}: {'PASS' if verdict.passed else 'FAIL'}",
            "",
            verdict.summary + ".",
            "",
            "| figure | value |",
            "|---|---|",
            *(f"| {name} | {value:.4g} |" for name, value in verdict.figures.items()),
            "",
            *([f"![{scenario.name}]({png})", ""] if png else []),
        ]
    return "\n".join(lines)
