"""`rosrun thesis_demos run_bimanual --cell FILE`: the ninth demonstration on a running cell (README,
Bimanual).

The cell must run with the demonstration's scene (thesis_demos.bimanual.scene_args; `make demo CELL=` does
it). Prints the verdict lines, writes bimanual.png, report.md and the recorded series (bimanual.npz) into
`--output`; exit 0 when it passed, 1 when it failed or a stack did not answer, 2 for a cell file that cannot
be read or has no `bimanual`.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Sequence

__all__ = ["main"]


def _plot(rec, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from thesis_demos.analysis import moving_mean
    from thesis_demos.bimanual import BIMANUAL_FORCE, BIMANUAL_TOLERANCE

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    top.plot(rec.force_t, rec.force, lw=0.5, color="0.7", label="presser's contact force")
    if rec.force_t.size > 1:
        means = moving_mean(rec.force_t, rec.force, 0.05)
        top.plot(rec.force_t[len(rec.force_t) - len(means):], means, label="50 ms means")
    for bound in (BIMANUAL_FORCE - BIMANUAL_TOLERANCE, BIMANUAL_FORCE + BIMANUAL_TOLERANCE):
        top.axhline(bound, ls="--", color="k", lw=0.8)
    top.axvspan(0.0, rec.slide_end, color="C2", alpha=0.1, label="slide")
    top.set_ylabel("force [N]")
    top.legend(loc="lower right")
    bottom.plot(rec.holder_t, (rec.holder_z - rec.held_z) * 1000.0,
                label="holder's tool tip z - where it held")
    bottom.axhspan(-1.0, 1.0, color="C2", alpha=0.1)
    bottom.set_xlabel("time from the slide's start [s]")
    bottom.set_ylabel("[mm]")
    bottom.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cell", required=True,
                        help="the cell file (its `bimanual` says where the arms meet)")
    parser.add_argument("--output", default="demo_output/bimanual",
                        help="folder for the plot and report.md")
    parser.add_argument("--sensor-frame", default="ft_sensor")
    parser.add_argument("--tasks", default="task_server", help="the presser's task_server, in its namespace")
    parser.add_argument("--world-frame", default="world", help="the cell's tf frame above every arm's")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds to wait for the stacks")
    args = parser.parse_args(argv)
    from mujoco_driver.cell_file import CellFileError, load_cell

    try:
        spec = load_cell(args.cell).bimanual
    except CellFileError as exc:
        print(f"[bimanual] {exc}", file=sys.stderr)
        return 2
    if spec is None:
        print(f"[bimanual] {args.cell} has no `bimanual`: where its arms meet", file=sys.stderr)
        return 2
    import rospy

    from thesis_demos.bimanual import judge
    from thesis_demos.bimanual_client import BimanualFlow
    from thesis_demos.stack_client import Names, StackClient

    rospy.init_node("run_bimanual", anonymous=True)
    started = time.monotonic()

    def stack(ns: str) -> StackClient:
        return StackClient(Names().within(ns), args.timeout)

    try:
        holder, presser = stack(spec.holder), stack(spec.presser)
        flow = BimanualFlow(holder, presser, f"/{spec.presser}/{args.tasks}", args.world_frame)
        rec = flow.run(spec, args.sensor_frame, args.timeout)
    except (RuntimeError, TimeoutError, rospy.ROSException) as exc:
        print(f"[FAIL] bimanual: {exc}", flush=True)
        return 1
    verdict = judge(rec)
    os.makedirs(args.output, exist_ok=True)
    _plot(rec, os.path.join(args.output, "bimanual.png"))
    import numpy as np

    np.savez(os.path.join(args.output, "bimanual.npz"), force_t=rec.force_t, force=rec.force,
             holder_t=rec.holder_t, holder_z=rec.holder_z, slide_end=rec.slide_end, held_z=rec.held_z,
             returned_z=rec.returned_z)
    title = (f"Bimanual: {spec.holder} holds a plate (spring on Z), {spec.presser} presses it and slides "
             f"{abs(spec.slide[0]) * 1000 + abs(spec.slide[1]) * 1000:.0f} mm")
    with open(os.path.join(args.output, "report.md"), "w", encoding="utf-8") as handle:
        handle.write(f"# {title}: {'PASS' if verdict.passed else 'FAIL'}\n\n")
        handle.write("".join(f"- {line}\n" for line in verdict.lines))
        handle.write(f"\n{time.monotonic() - started:.0f} s of wall time.\n\n![bimanual](bimanual.png)\n")
    for line in verdict.lines:
        print(f"  {line}", flush=True)
    print(f"[{'PASS' if verdict.passed else 'FAIL'}] bimanual: {title}", flush=True)
    return 0 if verdict.passed else 1
