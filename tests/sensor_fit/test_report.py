"""sensor_fit.report on a generated recording's fit: the profile's keys and the commented YAML."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from sensor_fit.noise_model import fit_recording
from sensor_fit.report import profile_section, yaml_text
from sensor_fit_testing import DRIFT, WHITE


def test_profile_section_and_yaml(fast):
    result = fit_recording(fast.t, fast.w, source="fast.csv")
    section = profile_section(result)
    assert list(section) == ["noise_force", "noise_torque", "drift_force", "drift_torque",
                             "drift_time_constant", "contact_shift_fraction", "contact_shift_threshold"]
    assert np.allclose(section["noise_force"], WHITE[:3], rtol=0.15)
    assert np.allclose(section["drift_torque"], DRIFT[3:], rtol=0.15)
    assert section["contact_shift_threshold"] == pytest.approx(0.5 * fast.peak, abs=1.0)
    text = yaml_text(result)
    assert yaml.safe_load(text) == {"wrench": section}
    lines = text.splitlines()
    for key in section:
        i = next(j for j, line in enumerate(lines) if line.startswith(f"  {key}:"))
        assert lines[i - 1].startswith("  # ") and "fast.csv" in lines[i - 1]
    assert lines[0] == "# Sensor model fitted by sensor_fit's fit_sensor from fast.csv."
