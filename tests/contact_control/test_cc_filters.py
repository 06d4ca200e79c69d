"""Low-pass filter: unit DC gain (the original's typo gave 1.129 / 1.546), and it does filter."""

import math

import pytest
from contact_control.filters import LowPass, butterworth_coefficients, dc_gain

SETTINGS = [  # (name, lp_filter_delta_t [s], lp_filter_cutoff_freq [Hz], DC gain with the original's typo)
    ("panda", 0.62, 0.53, 1.129),
    ("defaults", 0.2, 0.6, 1.546),
]


@pytest.mark.parametrize(("name", "delta_t", "cutoff", "typo_gain"), SETTINGS)
def test_original_typo_reproduces_the_documented_gain(name, delta_t, cutoff, typo_gain):
    assert dc_gain(butterworth_coefficients(delta_t, cutoff, legacy_typo=True)) == pytest.approx(
        typo_gain, abs=5e-4
    )


@pytest.mark.parametrize(("name", "delta_t", "cutoff", "typo_gain"), SETTINGS)
def test_our_filter_has_unit_dc_gain(name, delta_t, cutoff, typo_gain):
    assert dc_gain(butterworth_coefficients(delta_t, cutoff)) == pytest.approx(1.0, abs=1e-12)
    # And a steady force really comes out unchanged (started from zero, not primed on the step).
    lp = LowPass(delta_t, cutoff, channels=2)
    lp.reset([0.0, 0.0])
    for _ in range(400):
        out = lp.step([10.0, -3.0])
    assert out == pytest.approx([10.0, -3.0], abs=1e-9)


@pytest.mark.parametrize(("name", "delta_t", "cutoff", "typo_gain"), SETTINGS)
def test_filter_attenuates_fast_changes(name, delta_t, cutoff, typo_gain):
    lp = LowPass(delta_t, cutoff, channels=1)
    outputs = [lp.step([5.0 * (-1) ** n])[0] for n in range(200)]
    # A sign flip every sample (the Nyquist frequency) is removed entirely by this design.
    assert max(abs(y) for y in outputs[100:]) < 0.05


def test_first_sample_passes_without_transient():
    lp = LowPass(0.2, 0.6)
    assert lp.step([1.0, 2.0, 3.0, 4.0, 5.0, 6.0]) == pytest.approx([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])


@pytest.mark.parametrize(
    ("delta_t", "cutoff"), [(0.0, 1.0), (0.1, 0.0), (0.1, 5.0), (-1.0, 1.0), (math.nan, 1.0)]
)
def test_invalid_design_is_refused(delta_t, cutoff):
    with pytest.raises(ValueError):
        butterworth_coefficients(delta_t, cutoff)
