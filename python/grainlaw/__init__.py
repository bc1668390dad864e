"""grainlaw: discrete-element simulations of granular media turned into calibrated continuum laws.

Python bindings of the grainlaw Rust toolkit (PyO3 + numpy). Units are SI; 2D quantities are
per metre of thickness; stress tensors are tension positive, while the fits take
compressive-positive magnitudes (as ``grainlaw fit`` does).

- ``run(scenario, overrides, out, progress, allow_suspect)``: a scenario end to end
  (simulation, homogenisation, fits), as ``grainlaw run``; returns the summary, the tables as
  arrays, the laws and the verdict. A run judged ``refused`` raises ``ResultRefused``; one
  judged ``suspect`` raises ``ResultSuspect`` unless ``allow_suspect=True``: as loud as the
  command line's exit status 3.
- ``World`` / ``Snapshot``: the contact-dynamics engine (Moreau–Jean, Coulomb friction).
- ``grain_stresses``, ``mean_stress``, ``solid_fraction``, ``coordination``, ``fabric``:
  homogenisation of a snapshot.
- ``read_snapshots(format, files, ...)``: snapshots of LAMMPS/LIGGGHTS, LMGC90 or plain
  grainlaw-snapshot-v1 files, as ``grainlaw homogenise --from`` reads them, for the functions
  above.
- ``homogenise(format, files, out, ...)``: ``grainlaw homogenise --from FORMAT FILES --out
  OUT`` itself (CSV tables, figures, VTK, summary.json); returns the summary and the paths.
- ``continuum(case, law, out, dem=..., ...)``: a calibrated μ(I) law run in the continuum
  solver Gerris (``"column-collapse"``, ``"inclined-plane"``), compared with a DEM run, as
  ``grainlaw continuum``; returns the summary, the front and profiles as arrays, the comparison.
- ``fit_janssen``, ``fit_janssen_kmu``, ``fit_wall_law``, ``fit_mu_i``, ``fit_mu_i_linear``,
  ``fit_phi_i``, ``fit_mohr_coulomb`` (and the generic ``fit``): laws
  with confidence intervals, as ``Law`` objects; ``load_law`` reads a calibrated-law JSON.

Errors: every exception raised is a ``GrainlawError``: ``InputError`` (bad input),
``FitRefused`` (valid data that do not support the law; ``reason``, ``suggestion``),
``SolverError`` (a step failed), ``OutputError`` (a file could not be written or read),
``ResultRefused`` / ``ResultSuspect`` (a run's verdict; ``verdict``, ``reasons``, ``result``).
Every ``Law`` has a ``verdict`` (``ok`` for a fit that passed its checks).
A run stopped by Ctrl-C raises ``KeyboardInterrupt``.
"""

from __future__ import annotations

from typing import Optional

from ._grainlaw import (
    FitRefused,
    GrainlawError,
    InputError,
    Law,
    OutputError,
    ResultRefused,
    ResultSuspect,
    Snapshot,
    SolverError,
    World,
    __version__,
    continuum,
    coordination,
    fabric,
    fit,
    grain_stresses,
    homogenise,
    law_from_json,
    load_law,
    mean_stress,
    read_snapshots,
    run,
    scenarios,
    solid_fraction,
)

__all__ = [
    "GrainlawError",
    "InputError",
    "FitRefused",
    "SolverError",
    "OutputError",
    "ResultRefused",
    "ResultSuspect",
    "Law",
    "Snapshot",
    "World",
    "__version__",
    "continuum",
    "coordination",
    "fabric",
    "fit",
    "read_snapshots",
    "fit_janssen",
    "fit_janssen_kmu",
    "fit_mohr_coulomb",
    "fit_mu_i",
    "fit_mu_i_linear",
    "fit_phi_i",
    "fit_wall_law",
    "grain_stresses",
    "homogenise",
    "law_from_json",
    "load_law",
    "mean_stress",
    "run",
    "scenarios",
    "solid_fraction",
]


def _columns(**cols):
    """The columns that were given (None: absent)."""
    return {k: v for k, v in cols.items() if v is not None}


def fit_janssen(
    z,
    sigma_v,
    sigma_h,
    *,
    width: float,
    bulk_density: float,
    wall_friction: float,
    tau_w=None,
    gravity: float = 9.81,
    depth_min: Optional[float] = None,
    depth_max: Optional[float] = None,
    full_mobilisation: bool = False,
    confidence: float = 0.95,
) -> Law:
    """Janssen's law σ_v(z) = (ρ_b g W / (2 K μ_w)) (1 − exp(−2 K μ_w z / W)), σ_h = K σ_v,
    τ_w = μ_w σ_h (Janssen 1895; docs/physics.md §3.1), fitted jointly for K and μ_w.

    z: depth below the free surface (m); sigma_v, sigma_h, tau_w: vertical, horizontal (wall
    normal) and wall shear stress (Pa, compressive positive); width: W (m); bulk_density: ρ_b
    (kg/m³); wall_friction: the grain–wall μ, an upper bound of μ_w; gravity (m/s²);
    depth_min/depth_max: fit window (m); full_mobilisation: fix μ_w = wall_friction.
    Returns a Law with parameters ``K`` and ``mu_w`` (and derived quantities such as
    ``K_mu_w``).
    """
    return fit(
        "janssen",
        _columns(z_m=z, sigma_v_Pa=sigma_v, sigma_h_Pa=sigma_h, tau_w_Pa=tau_w),
        {
            "width_m": width,
            "bulk_density_kg_m3": bulk_density,
            "wall_friction": wall_friction,
            "gravity_m_s2": gravity,
            "depth_min_m": depth_min,
            "depth_max_m": depth_max,
            "full_mobilisation": 1.0 if full_mobilisation else None,
        },
        confidence=confidence,
    )


def fit_janssen_kmu(
    z,
    sigma_v,
    *,
    width: float,
    bulk_density: float,
    gravity: float = 9.81,
    depth_min: Optional[float] = None,
    depth_max: Optional[float] = None,
    confidence: float = 0.95,
) -> Law:
    """Janssen's σ_v(z) with the single parameter K μ_w (when σ_h is not measured).

    z (m), sigma_v (Pa, compressive positive), width W (m), bulk_density ρ_b (kg/m³),
    gravity (m/s²), depth_min/depth_max: fit window (m).
    """
    return fit(
        "janssen-kmu",
        _columns(z_m=z, sigma_v_Pa=sigma_v),
        {
            "width_m": width,
            "bulk_density_kg_m3": bulk_density,
            "gravity_m_s2": gravity,
            "depth_min_m": depth_min,
            "depth_max_m": depth_max,
        },
        confidence=confidence,
    )


def fit_wall_law(
    slip_velocity,
    mu_eff=None,
    *,
    tau_w=None,
    sigma_w=None,
    grain_diameter: float,
    gravity: float = 9.81,
    confidence: float = 0.95,
) -> Law:
    """Wall friction against slip velocity: the exponential, hyperbolic and power forms
    (``wall-law-exponential`` and so on) fitted, the lowest AIC among those accepted kept (the
    ranking is in ``law.to_dict()["model_selection"]``).

    slip_velocity (m/s); mu_eff = τ_w/σ_w, or tau_w and sigma_w (Pa, compressive positive);
    grain_diameter d (m); gravity (m/s²).
    """
    return fit(
        "wall-law",
        _columns(slip_velocity_m_s=slip_velocity, mu_eff=mu_eff, tau_w_Pa=tau_w, sigma_w_Pa=sigma_w),
        {"grain_diameter_m": grain_diameter, "gravity_m_s2": gravity},
        confidence=confidence,
    )


def _rheology(law, I, y, yname, grain_diameter, grain_density, pressure, confidence):
    cols = {"I": I, yname: y}
    if pressure is not None:
        cols["P_Pa"] = pressure
    return fit(
        law,
        cols,
        {"grain_diameter_m": grain_diameter, "grain_density_kg_m3": grain_density},
        confidence=confidence,
    )


def fit_mu_i(I, mu, *, grain_diameter: float, grain_density: float, pressure=None, confidence: float = 0.95) -> Law:
    """μ(I) = μ_s + (μ_2 − μ_s) I / (I + I_0) (Jop, Forterre & Pouliquen 2006; docs/physics.md §3.3).

    I: inertial number I = γ̇ d / √(P/ρ_s); mu: stress ratio τ/P; grain_diameter d (m) and
    grain_density ρ_s (kg/m³) are recorded in the law (its form in γ̇ and P); pressure: P (Pa)
    of each point, optional. Parameters ``mu_s``, ``mu_2``, ``I_0``.
    """
    return _rheology("mu-i", I, mu, "mu", grain_diameter, grain_density, pressure, confidence)


def fit_mu_i_linear(I, mu, *, grain_diameter: float, grain_density: float, pressure=None, confidence: float = 0.95) -> Law:
    """μ(I) = μ_s + b I, the linear form for data that do not reach the saturation of μ(I).

    Arguments as ``fit_mu_i``; parameters ``mu_s``, ``b``.
    """
    return _rheology("mu-i-linear", I, mu, "mu", grain_diameter, grain_density, pressure, confidence)


def fit_phi_i(I, phi, *, grain_diameter: float, grain_density: float, pressure=None, confidence: float = 0.95) -> Law:
    """φ(I) = φ_max − a I (da Cruz et al. 2005; docs/physics.md §3.3), valid over the I of the data.

    I: inertial number; phi: solid fraction; other arguments as ``fit_mu_i``. Parameters
    ``phi_max`` and ``a`` (the slope −dφ/dI). The former ``fit_phi_i_linear`` fitted the same
    line: the two are merged into this one.
    """
    return _rheology("phi-i", I, phi, "phi", grain_diameter, grain_density, pressure, confidence)


def fit_mohr_coulomb(
    *,
    p=None,
    q=None,
    sigma_xx=None,
    sigma_yy=None,
    sigma_xy=None,
    sigma_n=None,
    tau=None,
    cohesionless: bool = False,
    confidence: float = 0.95,
) -> Law:
    """Mohr–Coulomb envelope τ = c + σ_n tan φ (c: ``cohesion``, φ: ``friction_angle``) from stress states at yield (a conic program,
    Clarabel; docs/physics.md §3.4). Give one of: ``p`` and ``q``, the centre and radius of
    each Mohr circle (Pa, compressive positive); ``sigma_xx``, ``sigma_yy``, ``sigma_xy``, 2D
    tensors (Pa, **tension positive**); ``sigma_n`` and ``tau`` on the failure plane (Pa).
    cohesionless: fix c = 0. Parameters ``friction_angle`` (rad; also in degrees in
    ``law.to_dict()``) and ``cohesion`` (Pa).
    """
    cols = _columns(
        p_Pa=p,
        q_Pa=q,
        sigma_xx_Pa=sigma_xx,
        sigma_yy_Pa=sigma_yy,
        sigma_xy_Pa=sigma_xy,
        sigma_n_Pa=sigma_n,
        tau_Pa=tau,
    )
    return fit("mohr-coulomb", cols, {"cohesion": 0.0} if cohesionless else None, confidence=confidence)
