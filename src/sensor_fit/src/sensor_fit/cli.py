"""The ``fit_sensor`` command: reads a recording, fits it, prints the report and writes the profile's
``wrench:`` section (``--write-yaml``). ``python -m sensor_fit`` runs it too; see ``--help``."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from sensor_fit.errors import SensorFitError
from sensor_fit.noise_model import METHODS, fit_recording
from sensor_fit.recordings import CSV_LAYOUTS, TIME_UNITS, load_recording
from sensor_fit.report import format_report, yaml_text

__all__ = ["main"]


def _window_arg(text: str) -> tuple[float | None, float | None]:
    try:
        a, b = text.split(":")
        return (float(a) if a.strip() else None, float(b) if b.strip() else None)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected T0:T1 in seconds (e.g. 0:0.8, -0.8: for the last 0.8 s), "
                                         f"got {text!r}") from None


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="fit_sensor",
        description="Fit a force/torque sensor's noise model (offset, white noise, AR(1) drift, rate, "
                    "jitter, jumps, offset shift after contact) from a recording, and write it as a driver "
                    "profile's wrench section.")
    p.add_argument("recording", help="a ROS 1 bag (geometry_msgs/WrenchStamped topic) or a CSV")
    p.add_argument("--topic", help="the bag's wrench topic (default: its only WrenchStamped topic)")
    p.add_argument("--rest", action="append", type=_window_arg, metavar="T0:T1",
                   help="a rest window [s] from the recording's start (negative: from its end; write "
                        "--rest=-0.8: for the last 0.8 s); repeat it: the first is fitted, the offset change "
                        "is from the first to the last in time. Default: found in the data")
    p.add_argument("--min-rest", type=float, default=0.3, help="shortest detected rest window [s] (0.3)")
    p.add_argument("--csv-layout", choices=CSV_LAYOUTS, default="auto",
                   help="ur_logger: sec,nsec,fx,fy,fz,tx,ty,tz without header, time rebuilt from nsec")
    p.add_argument("--columns", help="the CSV's column names, comma-separated (fx..tz, t; - to skip one)")
    p.add_argument("--time-column", help="the CSV's time column (name or 0-based index)")
    p.add_argument("--time-unit", choices=sorted(TIME_UNITS), help="unit of the CSV's time column")
    p.add_argument("--rate", type=float, help="sample rate [Hz] of a CSV without a time column")
    p.add_argument("--method", choices=METHODS, default="whittle",
                   help="whittle: spectrum fitted by maximum likelihood (default); "
                        "acf: autocovariance least squares")
    p.add_argument("--write-yaml", metavar="OUT.yaml", help="write the profile's wrench section there")
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point: prints the report; errors are one line on stderr, exit status 2."""
    args = _parser().parse_args(argv)
    notes: list[str] = []
    try:
        columns = args.columns.split(",") if args.columns else None
        t, w = load_recording(args.recording, topic=args.topic, notes=notes, columns=columns,
                              layout=args.csv_layout, time_column=args.time_column, time_unit=args.time_unit,
                              rate=args.rate)
        result = fit_recording(t, w, rest=args.rest, min_rest=args.min_rest,
                               source=os.path.basename(args.recording)
                               + (f" {args.topic}" if args.topic else ""), notes=notes, method=args.method)
        sys.stdout.write(format_report(result) + "\n")
        if args.write_yaml:
            try:
                with open(args.write_yaml, "w") as stream:
                    stream.write(yaml_text(result))
            except OSError as exc:
                raise SensorFitError(f"cannot write {args.write_yaml}: {exc.strerror}") from None
            sys.stdout.write(f"wrote {args.write_yaml}\n")
    except SensorFitError as exc:
        sys.stderr.write(f"fit_sensor: error: {exc}\n")
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
