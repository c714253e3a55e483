"""Host-side design of the LQI rate controller (docs/gnc.md §5): the linear plant at one flight
condition, its discretisation, the discrete LQR gain of the augmented plant and a gain table over
a grid of speed and altitude. numpy/scipy only, run once per campaign, never traced.

Frames and states: body axes FRD (x forward along the axis, y right, z down). The plant state is
x = [v, w, p, q, r, u_y, u_p, u_r]: v, w the body y, z components of the velocity [m/s]; p, q, r
the body rates [rad/s]; u_y, u_p, u_r the servos' virtual yaw, pitch and roll deflections [rad].
The augmented state appends e = [e_p, e_q, e_r] = ∫k_int·(−p, −q, −r) dt [rad], k_int the integrator gains
the flight steps them with (``GuidanceParams.integrator_gain``); the inputs are the three commanded virtual
deflections [rad]; the control law is u = −K x.

The loop as flown (``flown_loop``): at each period start the flight steps the integrators e += k_int·T·(ω_cmd − ω)
(forward Euler, ``guidance.integrate_errors``), then commands u = −K [x; e] with the stepped e, held over the
period (the plant's zero-order hold). The design discretises the continuous augmentation instead (ZOH or Euler);
the two integrator discretisations differ by half a step of the rate's integral, and their gains' flown loops
by ≤ 5e-5 in spectral radius on the Lynx grid (docs/conventions.md, Closed loop).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import scipy.linalg

from ..env.atmosphere import isa

N_PLANT = 8  # [v, w, p, q, r, u_y, u_p, u_r]
N_INPUT = 3  # virtual commands (yaw, pitch, roll)
N_STATE = N_PLANT + N_INPUT  # with the integrators [e_p, e_q, e_r]
RATE_INDEX = (2, 3, 4)  # p, q, r in the plant state, the rates the integrators follow

# The weights the thesis flew (docs/gnc.md §5), on the augmented state and the three inputs.
THESIS_Q = np.diag([0.0, 0.0, 0.0, 5.0, 5.0, 0.0, 0.0, 0.0, 10.0, 10.0, 10.0])
THESIS_R = 100.0 * np.eye(N_INPUT)
THESIS_DT = 0.02  # GNC period [s]
THESIS_OMEGA_A = 1.0 / 0.0769  # servo bandwidth, first order 1/(0.0769 s + 1) [rad/s]


class FlownLoopUnstable(ValueError):
    """A design whose loop as flown (``flown_loop``) is not stable at a grid point."""


class PlantPoint(NamedTuple):
    """The rocket at one design point, as docs/gnc.md §5's linear plant needs it.

    Coefficients per rad about the moment reference, the thesis's linear model (docs/lynx.md) and its
    conventions: β = v/u, α = w/u, δ the virtual deflection of the channel. Damping as the thesis
    writes it: the *force* damping cy_r, cn_q per ω·d/V (thesis 154; rocketmc's aero models use
    ω·d/(2V), i.e. twice that, 308), the *moment* damping cl_p, cm_q, cn_r per ω·d/(2V).
    cn_alpha, cn_q, cn_delta are the normal force's (CN = −Z/(q̄S)); cn_yaw_beta, cn_r,
    cn_yaw_delta the yawing moment's (Cn). Yaw inertia is taken equal to pitch inertia (Izz = Iyy).

    mass [kg]; ixx, iyy [kg·m²]; area S [m²]; diameter d [m]; speed u, the axial body speed [m/s];
    density ρ [kg/m³]; omega_a, the servo bandwidth [rad/s].
    """

    cy_beta: float
    cy_r: float
    cy_delta: float
    cn_alpha: float
    cn_q: float
    cn_delta: float
    cl_p: float
    cl_delta: float
    cm_alpha: float
    cm_q: float
    cm_delta: float
    cn_yaw_beta: float
    cn_r: float
    cn_yaw_delta: float
    mass: float
    ixx: float
    iyy: float
    area: float
    diameter: float
    speed: float
    density: float
    omega_a: float = THESIS_OMEGA_A


class Design(NamedTuple):
    """One discrete LQR design: gain (m, n) for u = −K x; P (n, n) the DARE solution;
    spectral_radius max|eig(Ad − Bd K)| [-]; residual the DARE residual relative to ‖P‖ [-]."""

    gain: np.ndarray
    riccati: np.ndarray
    spectral_radius: float
    residual: float


class Schedule(NamedTuple):
    """Gains over a grid: speeds (n_speed,) [m/s]; altitudes (n_alt,) [m above MSL];
    gains (n_speed, n_alt, 3, 11); spectral_radius (the designed loop's) and residual (n_speed, n_alt) [-];
    flown_radius (n_speed, n_alt) [-], the spectral radius of the loop as flown (``flown_loop``)."""

    speeds: np.ndarray
    altitudes: np.ndarray
    gains: np.ndarray
    spectral_radius: np.ndarray
    residual: np.ndarray
    flown_radius: np.ndarray


def density(altitude_msl: float) -> float:
    """ISA density [kg/m³] at a geometric altitude above mean sea level [m], as a host float."""
    return float(isa(altitude_msl).density)


def lqi_plant(point: PlantPoint) -> tuple[np.ndarray, np.ndarray]:
    """Continuous plant ẋ = A x + B δ_cmd of docs/gnc.md §5: A (8, 8), B (8, 3) in SI units (rad, m/s, rad/s).

    k_m = ρS/(2m), k_I = ρSd/(2Ixx), k_s = ρSd/(2Iyy); the lateral and rate equations are the
    rigid body's linearised about straight flight at axial speed u with zero rates.
    """
    c, u, d = point, point.speed, point.diameter
    k_m = point.density * point.area / (2.0 * point.mass)
    k_i = point.density * point.area * d / (2.0 * point.ixx)
    k_s = point.density * point.area * d / (2.0 * point.iyy)
    a = np.zeros((N_PLANT, N_PLANT))
    a[0, [0, 4, 5]] = c.cy_beta * k_m * u, c.cy_r * k_m * d * u - u, c.cy_delta * k_m * u**2
    a[1, [1, 3, 6]] = -c.cn_alpha * k_m * u, u - c.cn_q * k_m * d * u, -c.cn_delta * k_m * u**2
    a[2, [2, 7]] = c.cl_p * k_i * (d / 2.0) * u, c.cl_delta * k_i * u**2
    a[3, [1, 3, 6]] = c.cm_alpha * k_s * u, c.cm_q * k_s * (d / 2.0) * u, c.cm_delta * k_s * u**2
    a[4, [0, 4, 5]] = c.cn_yaw_beta * k_s * u, c.cn_r * k_s * (d / 2.0) * u, c.cn_yaw_delta * k_s * u**2
    actuators = np.arange(5, N_PLANT)
    a[actuators, actuators] = -point.omega_a
    b = np.zeros((N_PLANT, N_INPUT))
    b[actuators, np.arange(N_INPUT)] = point.omega_a
    return a, b


def rate_picker(n: int = N_PLANT) -> np.ndarray:
    """C (3, n): picks the body rates p, q, r out of the plant state."""
    c = np.zeros((N_INPUT, n))
    c[np.arange(N_INPUT), RATE_INDEX] = 1.0
    return c


def augment(a: np.ndarray, b: np.ndarray, integrator_gain=(1.0, 1.0, 1.0)) -> tuple[np.ndarray, np.ndarray]:
    """Append the integrators ė = −diag(k_int) C x (C picks p, q, r; ``integrator_gain`` k_int per axis [-]) to
    the continuous plant: A (11, 11), B (11, 3)."""
    c = np.diag(np.asarray(integrator_gain, float)) @ rate_picker(a.shape[0])
    a_aug = np.block([[a, np.zeros((a.shape[0], N_INPUT))], [-c, np.zeros((N_INPUT, N_INPUT))]])
    return a_aug, np.vstack([b, np.zeros((N_INPUT, b.shape[1]))])


def discretise(a: np.ndarray, b: np.ndarray, dt: float, method: str = "zoh") -> tuple[np.ndarray, np.ndarray]:
    """Discrete plant x_{k+1} = Ad x_k + Bd u_k over a step dt [s].

    "zoh": exact zero-order hold, expm([[A, B], [0, 0]]·dt) = [[Ad, Bd], [0, I]];
    "euler": forward Euler, Ad = I + A dt, Bd = B dt (what the thesis flew).
    """
    n, m = b.shape
    if method == "euler":
        return np.eye(n) + a * dt, b * dt
    if method == "zoh":
        block = np.zeros((n + m, n + m))
        block[:n, :n], block[:n, n:] = a, b
        e = scipy.linalg.expm(block * dt)
        return e[:n, :n], e[:n, n:]
    raise ValueError(f"unknown discretisation {method!r}: expected 'zoh' or 'euler'")


def lqi_gain(ad: np.ndarray, bd: np.ndarray, q: np.ndarray, r: np.ndarray, where: str = "the design point") -> Design:
    """Infinite-horizon discrete LQR of (Ad, Bd) with weights Q (n, n) ⪰ 0 and R (m, m) ≻ 0.

    P solves the DARE (scipy.linalg.solve_discrete_are), K = (R + BᵀPB)⁻¹BᵀPA. Raises ValueError
    naming ``where`` if the weights are not symmetric Q ⪰ 0, R ≻ 0, or if there is no stabilising solution:
    scipy finds none, or the closed loop of the one it returns has a spectral radius not below 1 (which of the two
    on a pencil with eigenvalues on the unit circle depends on LAPACK's rounding: the same refusal).
    """
    if not (np.allclose(q, q.T) and np.allclose(r, r.T)):
        raise ValueError(f"LQI design at {where}: the weights Q and R must be symmetric")
    if np.linalg.eigvalsh(q).min() < -1e-12 * max(1.0, np.abs(q).max()) or np.linalg.eigvalsh(r).min() <= 0.0:
        raise ValueError(f"LQI design at {where}: Q must be positive semi-definite and R positive definite")
    try:
        p = scipy.linalg.solve_discrete_are(ad, bd, q, r)
    except (np.linalg.LinAlgError, ValueError) as err:
        raise ValueError(f"LQI design at {where}: no stabilising DARE solution ({err})") from None
    bt_p = bd.T @ p
    gain = np.linalg.solve(r + bt_p @ bd, bt_p @ ad)
    spectral_radius = float(np.abs(np.linalg.eigvals(ad - bd @ gain)).max())
    if not np.isfinite(spectral_radius) or spectral_radius >= 1.0:
        raise ValueError(f"LQI design at {where}: no stabilising DARE solution (the closed loop's spectral radius "
                         f"{spectral_radius:.9g} is not below 1)")  # fmt: skip
    at_p = ad.T @ p
    lhs = at_p @ ad - p - at_p @ bd @ gain + q  # AᵀPA − P − AᵀPB(R + BᵀPB)⁻¹BᵀPA + Q
    residual = float(np.linalg.norm(lhs) / np.linalg.norm(p))
    return Design(gain, p, spectral_radius, residual)


def flown_loop(a: np.ndarray, b: np.ndarray, gain: np.ndarray, integrator_gain, dt: float) -> np.ndarray:
    """The closed loop as the flight steps it, (11, 11), on [x_k; e_k] (e_k the integrators before period k's
    step): e_{k+1} = e_k − T diag(k_int) C x_k (no command: the loop's own dynamics), u_k = −K_x x_k − K_e e_{k+1},
    x_{k+1} = Ad x_k + Bd u_k with (Ad, Bd) the exact zero-order hold of the continuous plant a (8, 8), b (8, 3)
    over T = dt [s]; gain K (3, 11), integrator_gain k_int (3,) [-]. Built from the plant, K and k_int only, not
    from the design's augmented plant."""
    ad, bd = discretise(a, b, dt, "zoh")
    k_x, k_e = gain[:, :N_PLANT], gain[:, N_PLANT:]
    integrate = np.hstack([-dt * np.diag(np.asarray(integrator_gain, float)) @ rate_picker(), np.eye(N_INPUT)])
    command = np.hstack([k_x, np.zeros((N_INPUT, N_INPUT))]) + k_e @ integrate  # u_k = −command [x_k; e_k]
    return np.vstack([np.hstack([ad, np.zeros((N_PLANT, N_INPUT))]) - bd @ command, integrate])


def gain_schedule(
    point_at: Callable[[float, float], PlantPoint],
    speeds,
    altitudes,
    dt: float = THESIS_DT,
    q: np.ndarray = THESIS_Q,
    r: np.ndarray = THESIS_R,
    method: str = "zoh",
    integrator_gain=(1.0, 1.0, 1.0),
) -> Schedule:
    """LQI gains over the grid speeds × altitudes ([m/s] × [m above MSL], each strictly increasing).

    ``point_at(speed, altitude)`` gives the plant there (mass, inertia and coefficients at the
    design point, ρ e.g. from ``density(altitude)``); each point is augmented with the integrator gains
    ``integrator_gain`` (k_int per axis [-], as flown), discretised with ``method`` over dt [s] and designed
    with ``lqi_gain``; its loop as flown (``flown_loop``) must be stable too. A failing point raises ValueError
    naming its speed and altitude.
    """
    speeds, altitudes = np.asarray(speeds, float), np.asarray(altitudes, float)
    for name, grid in (("speeds", speeds), ("altitudes", altitudes)):
        if grid.ndim != 1 or grid.size == 0 or np.any(np.diff(grid) <= 0.0):
            raise ValueError(f"gain schedule: {name} must be a non-empty, strictly increasing 1-D grid")
    gains = np.zeros((speeds.size, altitudes.size, N_INPUT, N_STATE))
    radius, residual, flown = (np.zeros(gains.shape[:2]) for _ in range(3))
    for i, speed in enumerate(speeds):
        for j, altitude in enumerate(altitudes):
            where = f"speed {speed:g} m/s, altitude {altitude:g} m"
            plant = lqi_plant(point_at(speed, altitude))
            design = lqi_gain(*discretise(*augment(*plant, integrator_gain), dt, method), q, r, where=where)
            gains[i, j], radius[i, j], residual[i, j] = design.gain, design.spectral_radius, design.residual
            flown[i, j] = np.abs(np.linalg.eigvals(flown_loop(*plant, design.gain, integrator_gain, dt))).max()
            if not flown[i, j] < 1.0:  # NaN included
                raise FlownLoopUnstable(f"LQI design at {where}: the loop as flown (integrator gains "
                                 f"{tuple(map(float, integrator_gain))}) is not stable, spectral radius "
                                 f"{flown[i, j]:.9g}")  # fmt: skip
    return Schedule(speeds, altitudes, gains, radius, residual, flown)
