"""The demonstrations' stop-on-contact force for a driver's sensor, from its profile's noise (pure; the
robot_setup README, *Real sensors*).

contact_control refuses a force limit below `noise_limit_sigmas` stds of its sensor's noise after the
low-pass filter (contact_control.noise_floor). The same estimate from the profile's wrench model (white noise
and AR(1) drift per axis, at the profile's rate) gives what each of the profile's variants resolves; the
demonstrations' limit for the driver is the largest of those, with a margin, rounded up, never below the
thesis's. A variant that needs more than CAP is left out: its demonstrations are [CANNOT] at run time.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from contact_control.noise_floor import filtered_fraction
from contact_control.params import ContactControlSettings
from mujoco_driver.profiles import DriverProfile, WrenchSpec, load_profile, variant_options

__all__ = ["CAP", "MARGIN", "DriverContactForce", "contact_force_for", "resolvable_force"]

#: The noise floor contact_control measures is the std of 25 samples (0.2 s at 125 Hz and more): about 20 %
#: off per axis, and the worst of three axes is taken; the derived limit keeps this factor above it.
MARGIN = 1.3
#: [N] a choice: a "stop on contact" limit above this is no longer the thesis's demonstration (its 0.5 N);
#: a variant that needs more gets no limit here and run_demos names its demonstrations [CANNOT].
CAP = 3.0
STEP = 0.5  # [N] limits are rounded up to this


def _triple(value: float | Sequence[float]) -> tuple[float, float, float]:
    if isinstance(value, (int, float)):
        return (float(value),) * 3
    return (float(value[0]), float(value[1]), float(value[2]))


def resolvable_force(spec: WrenchSpec, rate: float, cutoff: float | None = None,
                     sigmas: float | None = None) -> float:
    """The smallest force limit [N] contact_control accepts on this wrench: `sigmas` (its
    noise_limit_sigmas) filtered stds of the worst force axis; white noise and the drift pass the filter
    (cutoff [Hz], its lp_filter_cutoff_freq) separately."""
    settings = ContactControlSettings()
    cutoff = settings.lp_filter_cutoff_freq if cutoff is None else cutoff
    sigmas = settings.noise_limit_sigmas if sigmas is None else sigmas
    tau = spec.drift_time_constant
    lag1 = math.exp(-1.0 / (rate * tau)) if tau > 0.0 and rate > 0.0 else 0.0
    white = filtered_fraction(rate, cutoff)
    slow = filtered_fraction(rate, cutoff, lag1) if lag1 > 0.0 else 0.0
    worst = max(math.hypot(white * n, slow * d)
                for n, d in zip(_triple(spec.noise_force), _triple(spec.drift_force), strict=True))
    return sigmas * worst


@dataclass(frozen=True)
class DriverContactForce:
    """The demonstrations' force limit for one driver profile.

    Attributes:
        limit: [N] for demos.yaml's contact_force.drivers (the thesis's when every variant resolves it).
        variants: (variant in words, what it resolves [N]) per variant of the profile.
        cannot: The variants over CAP, in words.
    """

    limit: float
    variants: tuple[tuple[str, float], ...]
    cannot: tuple[str, ...]

    def comment(self) -> str:
        parts = [f"{name} resolves {force:.2g} N" for name, force in self.variants]
        text = "; ".join(parts)
        if self.cannot:
            text += f" ({', '.join(self.cannot)}: [CANNOT], over {CAP:g} N)"
        return text


def _words(options: dict[str, object]) -> str:
    return ", ".join(f"{k}={v}" for k, v in options.items()) or "default"


def contact_force_for(driver: str, thesis_limit: float) -> DriverContactForce:
    """The limit for `driver` (a mujoco_driver profile name or path) from each variant's wrench noise.

    Raises:
        mujoco_driver.profiles.ProfileError: An unknown or invalid profile.
    """
    variants: list[tuple[str, float]] = []
    for options in variant_options(driver):
        profile: DriverProfile = load_profile(driver, options)
        variants.append((_words(options), resolvable_force(profile.wrench, profile.publish_rate)))
    usable = [force for _, force in variants if force * MARGIN <= CAP]
    cannot = tuple(name for name, force in variants if force * MARGIN > CAP)
    needed = max(usable, default=0.0) * MARGIN
    limit = max(thesis_limit, math.ceil(needed / STEP - 1e-9) * STEP)
    return DriverContactForce(limit, tuple(variants), cannot)
