"""The motor winding's temperature rise along a run: the first-order thermal model
τ_th dΔT/dt = R_th P(t) − ΔT driven by the copper loss (:func:`thermal_rise`), and the
report's two temperature columns (:func:`temperature_rises`)."""

from __future__ import annotations

import numpy as np

from armdyn._runs import time_mean


def thermal_rise(t: np.ndarray, loss: np.ndarray, r_th: float, tau_th: float) -> np.ndarray:
    """Winding temperature rise of the first-order model τ_th dΔT/dt = R_th P(t) − ΔT from
    ΔT = 0, P linear between samples (exact per step)."""
    out = np.zeros_like(loss)
    for k in range(1, len(t)):
        h = t[k] - t[k - 1]
        if h <= 0.0:  # a repeated sample (an event's time): nothing elapses
            out[k] = out[k - 1]
            continue
        a = np.exp(-h / tau_th)
        slope = (loss[k] - loss[k - 1]) / h
        p1 = r_th * (loss[k] - tau_th * slope)
        p0 = r_th * (loss[k - 1] - tau_th * slope)
        out[k] = p1 + (out[k - 1] - p0) * a
    return out


def temperature_rises(
    t: np.ndarray, loss: np.ndarray, r_th: float, tau_th: float
) -> tuple[float, float]:
    """``(steady, peak)`` temperature rise [K] of a copper loss ``loss`` [W] along a run:
    steady = R_th · mean loss, peak = the largest rise of :func:`thermal_rise` from ΔT(0) = 0.
    NaN where the datasheet value is missing (R_th for both, a positive τ_th for the peak)."""
    steady, peak = np.nan, np.nan
    if np.isfinite(r_th):
        steady = r_th * time_mean(loss, t)
        if np.isfinite(tau_th) and tau_th > 0:
            peak = float(np.max(thermal_rise(t, loss, r_th, tau_th)))
    return steady, peak
