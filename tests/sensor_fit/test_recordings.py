"""sensor_fit.recordings on generated recordings: CSVs with a header, headerless or in the UR logger's layout
(the nanosecond field wrapping every second), and bags."""

from __future__ import annotations

import numpy as np
import pytest
from harness.bags import write_bag
from sensor_fit.errors import SensorFitError
from sensor_fit.recordings import load_bag, load_csv
from sensor_fit_testing import Synth, wrench_messages, write_ur_logger


def test_csv_readers(tmp_path, fast):
    header = tmp_path / "header.csv"
    t_us = 1_708_857_503_929_545 + np.round(fast.t * 1e6).astype(np.int64)
    with open(header, "w") as f:
        f.write("t,fx,fy,fz,tx,ty,tz\n")
        for ti, row in zip(t_us[:2000], fast.w[:2000], strict=True):
            f.write(f"{ti}," + ",".join(repr(float(v)) for v in row) + "\n")
    notes: list[str] = []
    t, w = load_csv(str(header), notes=notes)
    assert np.allclose(t, fast.t[:2000], atol=1e-6) and np.array_equal(w, fast.w[:2000])
    assert any("in us" in n for n in notes)
    named = tmp_path / "named.csv"
    with open(named, "w") as f:
        f.write("%time;field.wrench.force.x;field.wrench.force.y;field.wrench.force.z;field.wrench.torque.x;"
                "field.wrench.torque.y;field.wrench.torque.z;extra\n")
        for ti, row in zip(fast.t[:100], fast.w[:100], strict=True):
            f.write(f"{int(1.7e18 + ti * 1e9)};" + ";".join(repr(float(v)) for v in row) + ";0\n")
    t, w = load_csv(str(named))
    assert np.allclose(t, fast.t[:100], atol=1e-6) and np.array_equal(w, fast.w[:100])
    headerless = tmp_path / "six.csv"
    np.savetxt(headerless, fast.w[:100], delimiter=" ")
    with pytest.raises(SensorFitError, match="--rate"):
        load_csv(str(headerless))
    t, _ = load_csv(str(headerless), rate=100.0)
    assert t[-1] == pytest.approx(0.99)
    with pytest.raises(SensorFitError, match="no column for tx"):
        load_csv(str(headerless), columns=["fx", "fy", "fz", "-", "ty", "tz"], rate=100.0)


def test_ur_logger_csv_layout_rebuilds_the_time_from_nsec(tmp_path, fast):
    csv_path = tmp_path / "wrench.csv"
    write_ur_logger(csv_path, fast)
    t, w = load_csv(str(csv_path), layout="ur_logger")
    # %.6g of the nanoseconds keeps 6 digits: times good to 1 ms at worst, the unwrap exact over 42 s.
    assert len(t) == len(fast.t) and np.max(np.abs(t - fast.t)) < 1e-3
    assert np.allclose(w, fast.w, rtol=1e-5, atol=1e-5)


def test_bag_with_zero_stamps_uses_the_record_time(tmp_path, fast):
    short = Synth(fast.t[:200], fast.w[:200], fast.rate, fast.tau, 0, 0, (0, 0), ((0, 0), (0, 0)), 0, 0)
    bag = tmp_path / "zero.bag"
    write_bag(bag, wrench_messages("/wrench", short, zero_stamps=True))
    notes: list[str] = []
    t, w = load_bag(str(bag), None, notes)
    assert np.allclose(t, short.t, atol=2e-9) and np.array_equal(w, short.w)
    assert "record times" in " ".join(notes)
