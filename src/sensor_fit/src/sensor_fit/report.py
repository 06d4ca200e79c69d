"""A fit's outputs: the readable report, and the fitted keys of a driver profile's ``wrench:`` section (as
a dict and as commented YAML)."""

from __future__ import annotations

from sensor_fit.noise_model import CONTACT_FACTOR
from sensor_fit.recordings import AXES
from sensor_fit.rest_windows import REST_RULE
from sensor_fit.results import GAP_FACTOR, AxisFit, SensorFit

__all__ = ["format_report", "profile_section", "yaml_text"]


def _g(v: float, digits: int = 3) -> str:
    return f"{v:.{digits}g}"


def _tau_text(a: AxisFit) -> str:
    return f"{a.tau:.4g} s" if a.tau is not None else "undetermined"


def format_report(result: SensorFit) -> str:
    """A readable report: timing, rest windows, a table per axis, jumps and the offset change."""
    r = result
    lines = [f"recording: {r.source}" if r.source else "recording:"]
    lines += [f"  note: {n}" for n in r.notes]
    lines.append(f"samples: {r.n} over {r.duration:.3f} s")
    lines.append(f"rate: {r.rate:.1f} Hz (median interval {r.dt_median * 1e3:.3f} ms)")
    lines.append(f"jitter: interval std {r.dt_std * 1e3:.3f} ms, min {r.dt_min * 1e3:.3f} ms, "
                 f"max {r.dt_max * 1e3:.3f} ms")
    if r.gaps:
        shown = ", ".join(f"{g.length * 1e3:.1f} ms at {g.time:.3f} s" for g in r.gaps[:20])
        more = f" (+{len(r.gaps) - 20} more)" if len(r.gaps) > 20 else ""
        lines.append(f"gaps (> {GAP_FACTOR:g} median intervals): {len(r.gaps)}: {shown}{more}")
    else:
        lines.append(f"gaps (> {GAP_FACTOR:g} median intervals): none")
    how = "given" if r.fit_window.given else f"detected, >= {r.min_rest:g} s: {REST_RULE}"
    lines.append(f"rest windows ({how}):")
    for i, win in enumerate(r.rest_windows, 1):
        mark = "  <- fitted" if win == r.fit_window else ""
        mean = " ".join(f"{v:.3g}" for v in win.mean)
        lines.append(f"  #{i} {win.t0:.3f}-{win.t1:.3f} s ({win.n} samples), mean {mean}{mark}")
    span = r.fit_window.t1 - r.fit_window.t0
    lines.append(f"fit on {r.fit_window.t0:.3f}-{r.fit_window.t1:.3f} s ({r.fit_window.n} samples, "
                 f"{span:.3f} s): white noise + AR(1) drift per axis ({r.method} fit)")
    head = (f"{'axis':<5}{'unit':<5}{'offset':>10}{'std':>9}{'fit std':>9}{'white':>9}{'drift':>9}"
            f"{'tau':>13}{'lag1':>7}   largest jump")
    lines.append(head)
    for a, jump in zip(r.axes, r.jumps, strict=True):
        gap = ", after a gap" if jump.after_gap else ""
        lines.append(f"{a.axis:<5}{a.unit:<5}{a.offset:>10.4g}{a.std:>9.3g}{a.fitted_std:>9.3g}{a.white:>9.3g}"
                     f"{a.drift:>9.3g}{_tau_text(a):>13}{a.lag1:>7.2f}   "
                     f"{jump.value:+.3g} {jump.unit} at {jump.time:.3f} s{gap}")
    for a in r.axes:
        if a.note:
            lines.append(f"  {a.axis}: {a.note}")
    if r.common_tau is not None:
        lines.append(f"profile model (one tau = {r.common_tau:.4g} s, the median over the force axes): "
                     + ", ".join(f"{a}: white {_g(c[0])} drift {_g(c[1])}" for a, c in zip(AXES, r.common,
                                                                                            strict=True)))
    else:
        lines.append("profile model: tau undetermined on every force axis: no drift keys")
    s = r.shift
    if s is None:
        one = " (one found)" if len(r.rest_windows) == 1 else ""
        lines.append(f"offset change: needs two rest windows{one}")
    else:
        ch = " ".join(f"{a} {v:+.3g}" for a, v in zip(AXES, s.change, strict=True))
        i, j = r.rest_windows.index(s.first) + 1, r.rest_windows.index(s.last) + 1
        lines.append(f"offset change from rest #{i} ({s.first.t0:.2f}-{s.first.t1:.2f} s) to rest #{j} "
                     f"({s.last.t0:.2f}-{s.last.t1:.2f} s): {ch}")
        pf = ", ".join(f"{v:+.3g}" for v in s.peak_force)
        lines.append(f"  offset moved by {s.force_change:.3g} N after a {s.peak:.3g} N press (peak "
                     f"|F - offset #{i}| at {s.peak_time:.3f} s, F - offset = ({pf}) N): "
                     f"shift fraction {s.fraction:.3g}"
                     + ("" if r.contact else f" (peak < {CONTACT_FACTOR:g} x the force std: no contact, "
                                              "not used in the profile)"))
    return "\n".join(lines)


def _round(v: float, digits: int = 4) -> float:
    return float(f"{v:.{digits}g}")


def profile_section(result: SensorFit, digits: int = 4) -> dict:
    """The fitted keys of a driver profile's ``wrench`` section (WrenchSpec names).

    ``noise_force``/``noise_torque``: white std per axis [N, Nm]; ``drift_force``/``drift_torque``: AR(1)
    stationary std per axis and ``drift_time_constant`` [s]: one tau for all axes (the median of the force
    axes' determined taus; each axis's stds refitted with it), omitted when no force axis's tau is
    determined; ``contact_shift_fraction``: |force offset change| / peak press magnitude and
    ``contact_shift_threshold``: half the peak press magnitude [N] (a press of at least that size moves the
    offset), only when a contact was found between two rest windows.
    """
    r = result
    tau = r.common_tau
    source = r.common if tau is not None else [(a.white, 0.0) for a in r.axes]
    out: dict = {"noise_force": [_round(c[0], digits) for c in source[:3]],
                 "noise_torque": [_round(c[0], digits) for c in source[3:]]}
    if tau is not None:
        out["drift_force"] = [_round(c[1], digits) for c in source[:3]]
        out["drift_torque"] = [_round(c[1], digits) for c in source[3:]]
        out["drift_time_constant"] = _round(tau, digits)
    if r.shift is not None and r.contact:
        out["contact_shift_fraction"] = _round(r.shift.fraction, digits)
        out["contact_shift_threshold"] = _round(0.5 * r.shift.peak, digits)
    return out


def _yaml_value(v: object) -> str:
    if isinstance(v, list):
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"
    return repr(float(v))  # type: ignore[arg-type]


def yaml_text(result: SensorFit, source: str | None = None, digits: int = 4) -> str:
    """:func:`profile_section` as YAML under ``wrench:``, each key with a comment saying where it comes
    from (merge the keys into a profile's wrench section; topic, frame and model are not fitted)."""
    r = result
    name = source if source is not None else r.source
    win = r.fit_window
    where = f"{name}, rest {win.t0:.3f}-{win.t1:.3f} s ({win.n} samples at {r.rate:.1f} Hz)"
    section = profile_section(r, digits)
    comments = {
        "noise_force": f"[N] white-noise std fx fy fz, fitted from {where}",
        "noise_torque": f"[Nm] white-noise std tx ty tz, fitted from {where}",
        "drift_force": f"[N] AR(1) drift stationary std fx fy fz (tau fixed below), fitted from {where}",
        "drift_torque": f"[Nm] AR(1) drift stationary std tx ty tz, fitted from {where}",
        "drift_time_constant": "[s] AR(1) drift time constant: median over the force axes "
                               f"({', '.join(a.axis for a in r.axes[:3] if a.tau is not None)}), "
                               f"fitted from {where}",
    }
    if r.shift is not None:
        s = r.shift
        across = (f"{name}, rest {s.first.t0:.2f}-{s.first.t1:.2f} s vs {s.last.t0:.2f}-{s.last.t1:.2f} s: "
                  f"offset moved {s.force_change:.3g} N after a {s.peak:.3g} N press at {s.peak_time:.2f} s")
        comments["contact_shift_fraction"] = f"|offset change| / peak press, from {across}"
        comments["contact_shift_threshold"] = f"[N] half the peak press, from {across}"
    undetermined = [a.axis for a in r.axes[:3] if a.tau is None]
    lines = [f"# Sensor model fitted by sensor_fit's fit_sensor from {name}.",
             "# Merge these keys into a driver profile's wrench section (config/profiles/*.yaml)."]
    if "drift_time_constant" not in section:
        lines.append("# No drift keys: the drift's time constant is undetermined on every force axis "
                     "(see the report).")
        seen = [a.drift for a in r.axes]
        if any(v > 0.0 for v in seen):
            forces, torques = (", ".join(f"{v:.3g}" for v in part) for part in (seen[:3], seen[3:]))
            totals = ", ".join(f"{a.std:.3g}" for a in r.axes[:3])
            lines.append(f"# The window also shows a slow component (std at least {forces} N, {torques} Nm) "
                         f"left out: the emulated noise is quieter than the recording's ({totals} N in all).")
    elif undetermined:
        lines.append(f"# tau undetermined on {', '.join(undetermined)}: drift std refitted there with the "
                     "common tau (a slower component the window shows is not in it).")
    lines.append("wrench:")
    for key, value in section.items():
        lines.append(f"  # {comments[key]}")
        lines.append(f"  {key}: {_yaml_value(value)}")
    return "\n".join(lines) + "\n"
