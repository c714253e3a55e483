"""The two aerodynamic models behind one interface, and the wrench they share.

* ``TableAero`` (*interpolated*): the body table at (α, β, Mach, altitude) plus each canard
  panel's table at its own local incidence (the body's α/β and rates seen at the panel), its
  deflection and Mach; the panels superpose.
* ``LinearAero`` (*simplified*): derivatives tabulated over Mach (and altitude when the body table
  has it), linear in α, β, rates and deflections, CA0 plus a quadratic form in the deflections.
  ``simplify`` derives it from a ``TableAero`` at α = β = δ = 0, so the two agree at small angles
  by construction; ``from_virtual_commands`` writes the thesis's coefficients in the same form.

Both give an ``AeroCoefficients``; ``aero_wrench`` turns it into force and moment. Conventions are
those of ``aero.tables`` (body frame FRD, forces q̄S(−CA, CY, −CN), moments q̄Sd(Cl, Cm, Cn) about
``moment_ref_x_m``, rates non-dimensionalised as ω̂ = ω·d/(2V)).
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from ..math import Vec3
from ..math.table import Table, interpolate
from ..pytree import pytree_dataclass, static_field
from .airdata import AirData
from .canards import allocate, mix
from .tables import BODY_COEFFS, PANEL_COEFFS, AeroTables

CONTROL_OUTPUTS = ("CY", "CN", "Cl", "Cm", "Cn")
"""Rows of a ``LinearAero``'s control matrix: the coefficients a deflection changes linearly."""
LINEAR_DERIVATIVES = ("CA0", "CNa", "Cma", "Cl0", "CNq", "Cmq", "CYr", "Cnr", "Clp")
"""Mach-dependent scalars of a ``LinearAero`` (α, β derivatives per rad; the rocket is taken as
axisymmetric in its α and β derivatives: CY = −CNa·β, Cn = −Cma·β)."""


class AeroCoefficients(NamedTuple):
    """Force and moment coefficients at the moment reference point (everything but the body's rate
    damping, which is kept apart because it alone survives under a canopy), and the damping
    derivatives per ω̂."""

    ca: jnp.ndarray
    cy: jnp.ndarray
    cn: jnp.ndarray
    cl: jnp.ndarray
    cm: jnp.ndarray
    cn_yaw: jnp.ndarray
    cn_q: jnp.ndarray
    cm_q: jnp.ndarray
    cy_r: jnp.ndarray
    cn_r: jnp.ndarray
    cl_p: jnp.ndarray


@pytree_dataclass
class TableAero:
    """Interpolated model. reference_area_m2, reference_length_m: S [m²], d [m]; moment_ref_x_m:
    body-frame x of the moment reference [m]; body: ``Table`` over a subset of BODY_AXES with
    outputs BODY_COEFFS; canard_table: per-panel ``Table`` over PANEL_AXES with outputs
    PANEL_COEFFS, or None; canard_roll_rad: (n,) panel roll angles; canard_cp_x_m: body-frame x
    where the panels' normal force acts [m]; canard_cp_radius_m: its distance from the axis [m];
    drag_scale: multiplier on CA [-]; cl0: rolling-moment offset (fin misalignment) [-];
    power_on_ca: ``Table`` over ``mach`` of the axial-force change while the motor burns (the
    base drag the exhaust removes), output ``dCA``, or None."""

    reference_area_m2: jnp.ndarray
    reference_length_m: jnp.ndarray
    moment_ref_x_m: jnp.ndarray
    body: Table
    canard_table: Table | None
    canard_roll_rad: jnp.ndarray
    canard_cp_x_m: jnp.ndarray
    canard_cp_radius_m: jnp.ndarray
    drag_scale: jnp.ndarray
    cl0: jnp.ndarray
    power_on_ca: Table | None = None

    @classmethod
    def from_tables(cls, tables: AeroTables, reference_point_m, drag_scale=1.0, cl0=0.0) -> TableAero:
        """From host tables, the body frame's origin being ``reference_point_m`` from the nose tip."""
        body = Table.from_numpy(tables.body.axes, tables.body.values, tables.body.axis_names, BODY_COEFFS)
        canards = tables.canards
        if canards is None:
            canard_table, roll, cp_m, cp_radius = None, np.zeros(0), reference_point_m, 0.0
        else:
            t = canards.table
            canard_table = Table.from_numpy(t.axes, t.values, t.axis_names, PANEL_COEFFS)
            roll, cp_m, cp_radius = np.asarray(canards.roll_angles_rad), canards.cp_m, canards.cp_radius_m
        as_array = lambda x: jnp.asarray(x, dtype=float)  # noqa: E731
        return cls(
            as_array(tables.reference_area_m2),
            as_array(tables.reference_length_m),
            as_array(reference_point_m - tables.moment_reference_m),
            body,
            canard_table,
            as_array(roll),
            as_array(reference_point_m - cp_m),
            as_array(cp_radius),
            as_array(drag_scale),
            as_array(cl0),
        )

    @property
    def n_canards(self) -> int:
        return self.canard_roll_rad.shape[0]


@pytree_dataclass
class LinearAero:
    """Simplified model: ``table`` over ``mach`` (and ``altitude``) with outputs LINEAR_DERIVATIVES,
    then the control matrix ∂(CONTROL_OUTPUTS)/∂δ row by row (5·n), then the quadratic axial-force
    form Q (n·n, CA += δᵀQδ), n = n_canards. Other fields as in ``TableAero``."""

    reference_area_m2: jnp.ndarray
    reference_length_m: jnp.ndarray
    moment_ref_x_m: jnp.ndarray
    table: Table
    drag_scale: jnp.ndarray
    cl0: jnp.ndarray
    power_on_ca: Table | None
    n_canards: int = static_field()


def linear_output_names(n_canards: int) -> tuple[str, ...]:
    """Output names of a ``LinearAero`` table with ``n_canards`` deflections."""
    control = tuple(f"d{c}/dd{i + 1}" for c in CONTROL_OUTPUTS for i in range(n_canards))
    quadratic = tuple(f"CA_d{i + 1}d{j + 1}" for i in range(n_canards) for j in range(n_canards))
    return LINEAR_DERIVATIVES + control + quadratic


def _axis_value(name: str, air: AirData):
    return {"alpha": air.alpha, "beta": air.beta, "mach": air.mach, "altitude": air.altitude_msl}[name]


def _lookup(table: Table, air: AirData):
    return interpolate(table, tuple(_axis_value(name, air) for name in table.axis_names))


def rate_scale(aero: TableAero | LinearAero, air: AirData):
    """d/(2V) [s], which turns body rates into the non-dimensional ω̂ of the damping derivatives."""
    return 0.5 * aero.reference_length_m / jnp.maximum(air.airspeed, 1e-3)


def panel_normals(aero: TableAero):
    """(n_y, n_z) of each canard panel's normal (0, −cos φ, −sin φ), along which it pushes."""
    return -jnp.cos(aero.canard_roll_rad), -jnp.sin(aero.canard_roll_rad)


def panel_incidences(aero: TableAero, air: AirData, omega_hat: Vec3, cg_x_m):
    """Local incidence of each canard panel [rad] (n,): the angle, in the plane normal to the panel,
    of the air the panel meets, with the velocity the body rates add at its centre of pressure.

    omega_hat: body rates times d/(2V) [-]; cg_x_m: body-frame x of the centre of mass [m].
    """
    cos_b = jnp.cos(air.beta)
    direction = Vec3(cos_b * jnp.cos(air.alpha), jnp.sin(air.beta), cos_b * jnp.sin(air.alpha))
    normal_y, normal_z = panel_normals(aero)
    span_y, span_z = -normal_z, normal_y  # the span direction (0, sin φ, −cos φ)
    scale = 2.0 / aero.reference_length_m  # ω × r / V = ω̂ × r · 2/d
    arm_x = aero.canard_cp_x_m - cg_x_m
    radius = aero.canard_cp_radius_m
    # (ω̂ × r)·scale with r = (arm_x, radius·span_y, radius·span_z), written by components
    local_x = direction.x + scale * radius * (omega_hat.y * span_z - omega_hat.z * span_y)
    local_y = direction.y + scale * (omega_hat.z * arm_x - omega_hat.x * radius * span_z)
    local_z = direction.z + scale * (omega_hat.x * radius * span_y - omega_hat.y * arm_x)
    return jnp.arctan2(-(local_y * normal_y + local_z * normal_z), local_x)


def power_on_axial(aero: TableAero | LinearAero, air: AirData, burning):
    """Change of CA while the motor burns (0 when not burning or not modelled) [-]."""
    if aero.power_on_ca is None:
        return 0.0
    return jnp.where(burning, _lookup(aero.power_on_ca, air)[0][0], 0.0)


def table_coefficients(aero: TableAero, air: AirData, omega_hat: Vec3, cg_x_m, deflections, burning=False):
    """``AeroCoefficients`` of the interpolated model and whether a table was left (bool).

    deflections: (n,) canard deflections δ1..δn [rad], positive pushing the panel along its
    normal (0, −cos φ, −sin φ); burning: the motor is firing (power-on axial force).
    """
    values, out_of_range = _lookup(aero.body, air)
    body = dict(zip(BODY_COEFFS, values))
    ca, cy, cn, cl, cm, cn_yaw = (body[k] for k in ("CA", "CY", "CN", "Cl", "Cm", "Cn"))
    if aero.canard_table is not None:
        incidences = panel_incidences(aero, air, omega_hat, cg_x_m)
        panel = jax.vmap(lambda i, d: interpolate(aero.canard_table, (i, d, air.mach)))
        panel_values, panel_out = panel(incidences, jnp.asarray(deflections))
        panel_cn, panel_ca, panel_cr = (panel_values[:, k] for k in range(len(PANEL_COEFFS)))
        normal_y, normal_z = panel_normals(aero)
        # sums over the panels written out: a reduction is an XLA kernel of its own (5 % of a step)
        panels = range(aero.n_canards)
        force_y = sum(panel_cn[j] * normal_y[j] for j in panels)
        force_z = sum(panel_cn[j] * normal_z[j] for j in panels)
        arm = (aero.canard_cp_x_m - aero.moment_ref_x_m) / aero.reference_length_m
        ca = ca + sum(panel_ca[j] for j in panels)
        cy = cy + force_y
        cn = cn - force_z
        cl = cl - sum(panel_cr[j] for j in panels)
        cm = cm - arm * force_z
        cn_yaw = cn_yaw + arm * force_y
        for j in panels:
            out_of_range = out_of_range | panel_out[j]
    coefficients = AeroCoefficients(
        aero.drag_scale * (ca + power_on_axial(aero, air, burning)), cy, cn, cl + aero.cl0, cm, cn_yaw,
        body["CNq"], body["Cmq"], body["CYr"], body["Cnr"], body["Clp"],
    )  # fmt: skip
    return coefficients, out_of_range


def linear_coefficients(aero: LinearAero, air: AirData, deflections, burning=False):
    """``AeroCoefficients`` of the simplified model and whether its table was left (bool)."""
    values, out_of_range = _lookup(aero.table, air)
    n = aero.n_canards
    k = len(LINEAR_DERIVATIVES)
    c = dict(zip(LINEAR_DERIVATIVES, values[:k]))
    control = values[k : k + 5 * n].reshape(5, n)
    quadratic = values[k + 5 * n :].reshape(n, n)
    delta = jnp.asarray(deflections)
    # elementwise sums, not ``@``: a vmapped dot of a few numbers is a slow library call on CPU
    d_cy, d_cn, d_cl, d_cm, d_cn_yaw = jnp.sum(control * delta[None, :], axis=1) if n else jnp.zeros(5)
    drag_delta = jnp.sum(quadratic * delta[:, None] * delta[None, :]) if n else 0.0
    ca = aero.drag_scale * (c["CA0"] + power_on_axial(aero, air, burning)) + drag_delta
    coefficients = AeroCoefficients(
        ca,
        -c["CNa"] * air.beta + d_cy,
        c["CNa"] * air.alpha + d_cn,
        c["Cl0"] + aero.cl0 + d_cl,
        c["Cma"] * air.alpha + d_cm,
        -c["Cma"] * air.beta + d_cn_yaw,
        c["CNq"], c["Cmq"], c["CYr"], c["Cnr"], c["Clp"],
    )  # fmt: skip
    return coefficients, out_of_range


def aero_coefficients(aero: TableAero | LinearAero, air: AirData, omega_b: Vec3, cg_x_m, deflections, burning=False):
    """``AeroCoefficients`` of either model (chosen statically by its type) and the out-of-range flag.

    omega_b: body rates [rad/s]; cg_x_m: body-frame x of the centre of mass [m]; burning: the
    motor is firing.
    """
    if isinstance(aero, LinearAero):
        return linear_coefficients(aero, air, deflections, burning)
    return table_coefficients(aero, air, omega_b * rate_scale(aero, air), cg_x_m, deflections, burning)


def aero_wrench(aero: TableAero | LinearAero, c: AeroCoefficients, air: AirData, omega_b: Vec3, canopy_cl_p, under_canopy):
    """Aerodynamic force and moment (body frame) at the moment reference point [N, N·m].

    Under an open canopy (``under_canopy``) only the rate damping moments remain, the roll
    damping being the canopy's ``canopy_cl_p``.
    """
    s, d = aero.reference_area_m2, aero.reference_length_m
    qs = air.qbar * s
    rate = rate_scale(aero, air)
    flying = jnp.where(under_canopy, 0.0, 1.0)
    p_hat, q_hat, r_hat = omega_b.x * rate, omega_b.y * rate, omega_b.z * rate
    force = Vec3(-c.ca, c.cy + c.cy_r * r_hat, -(c.cn + c.cn_q * q_hat)) * (qs * flying)
    cl_p = jnp.where(under_canopy, canopy_cl_p, c.cl_p)
    moment = Vec3(
        c.cl * flying + cl_p * p_hat,
        c.cm * flying + c.cm_q * q_hat,
        c.cn_yaw * flying + c.cn_r * r_hat,
    ) * (qs * d)
    return force, moment


def simplify(aero: TableAero) -> LinearAero:
    """The simplified model of ``aero``: its derivatives at α = β = δ = 0 and zero rates, on the
    Mach (and altitude) grid of the body table (the canard table's Mach grid if the body has none).

    Central differences of the interpolated model itself (steps smaller than any table cell, so
    each is the mean slope of the two cells around zero); the quadratic axial force of each
    deflection is the secant at ±0.1 rad, since a multilinear table is piecewise linear in δ.
    Canard rate damping is taken about the moment reference point.
    """
    axes = dict(zip(aero.body.axis_names, aero.body.axes))
    if "mach" not in axes and aero.canard_table is not None:
        axes["mach"] = aero.canard_table.axes[2]
    grid_names = tuple(name for name in ("mach", "altitude") if name in axes) or ("mach",)
    grid_axes = tuple(np.asarray(axes.get(name, np.array([0.0, 1.0]))) for name in grid_names)
    unit = jax.tree_util.tree_map(jnp.asarray, TableAero(**{**vars(aero), "drag_scale": 1.0, "cl0": 0.0, "power_on_ca": None}))
    n = aero.n_canards

    def coefficients(mach, altitude, alpha, beta, omega_hat, deflections):
        air = AirData(1.0, alpha, beta, mach, 0.5, 1.0, altitude)
        return jnp.stack(table_coefficients(unit, air, omega_hat, unit.moment_ref_x_m, deflections)[0])

    def derivatives(mach, altitude):
        zero3, neutral = Vec3(0.0, 0.0, 0.0), jnp.zeros(n)

        def at(alpha=0.0, beta=0.0, omega=zero3, delta=neutral):
            return coefficients(mach, altitude, alpha, beta, omega, delta)

        h = 1e-4
        c0 = dict(zip(AeroCoefficients._fields, at()))
        d_alpha = dict(zip(AeroCoefficients._fields, (at(alpha=h) - at(alpha=-h)) / (2 * h)))
        d_rate = [
            dict(zip(AeroCoefficients._fields, (at(omega=Vec3(*e * h)) - at(omega=Vec3(*-e * h))) / (2 * h)))
            for e in np.eye(3)
        ]
        p, q, r = d_rate
        derivs = jnp.stack([
            c0["ca"], d_alpha["cn"], d_alpha["cm"], c0["cl"],
            c0["cn_q"] + q["cn"], c0["cm_q"] + q["cm"], c0["cy_r"] + r["cy"], c0["cn_r"] + r["cn_yaw"],
            c0["cl_p"] + p["cl"],
        ])  # fmt: skip
        control, quadratic = jnp.zeros((5, 0)), jnp.zeros((0, 0))
        if n:
            rows = jnp.array([AeroCoefficients._fields.index(f) for f in ("cy", "cn", "cl", "cm", "cn_yaw")])
            control = jnp.stack([(at(delta=h * e) - at(delta=-h * e)) / (2 * h) for e in np.eye(n)], axis=-1)[rows]
            s = 0.1  # secant half-width [rad]
            ca = [(at(delta=s * e)[0] + at(delta=-s * e)[0] - 2 * c0["ca"]) / (2 * s**2) for e in np.eye(n)]
            quadratic = jnp.diag(jnp.stack(ca))
        return jnp.concatenate([derivs, control.reshape(-1), quadratic.reshape(-1)])

    mesh = np.meshgrid(*grid_axes, indexing="ij")
    mach = mesh[grid_names.index("mach")] if "mach" in grid_names else np.zeros_like(mesh[0])
    altitude = mesh[grid_names.index("altitude")] if "altitude" in grid_names else np.zeros_like(mesh[0])
    values = jax.jit(jax.vmap(derivatives))(jnp.asarray(mach.ravel()), jnp.asarray(altitude.ravel()))
    values = np.asarray(values).reshape(mesh[0].shape + (-1,))
    table = Table.from_numpy(grid_axes, values, grid_names, linear_output_names(n))
    return LinearAero(aero.reference_area_m2, aero.reference_length_m, aero.moment_ref_x_m, table,
                      aero.drag_scale, aero.cl0, aero.power_on_ca, n)  # fmt: skip


def from_virtual_commands(
    reference_area_m2, reference_length_m, moment_ref_x_m, ca0_mach, ca0, ca_u, cn_alpha, cn_delta,
    cm_alpha, cm_delta, cl0, cl_delta, cn_q, cy_r, cm_q, cl_p, drag_scale=1.0,
) -> LinearAero:  # fmt: skip
    """The thesis's linear model (coefficients per virtual command u = (yaw, pitch, roll, squeeze),
    ``aero.canards.mix``) as a ``LinearAero`` over fin deflections δ1..δ4. Traceable: every
    coefficient may be a dispersed value.

    With u = Mδ: the control matrix is B_u·M and the quadratic form Mᵀ·diag(ca_u)·M. All damping
    derivatives per ω·d/(2V) (the thesis's force derivatives per ω·d/V are half these). Constant
    in Mach except CA0 (given at ``ca0_mach``).
    """
    mixing = jnp.asarray(np.array([mix(*e) for e in np.eye(4)]).T)  # u = mixing @ δ
    zero = jnp.zeros_like(jnp.asarray(cn_delta, dtype=float))
    b_u = jnp.stack([  # rows CONTROL_OUTPUTS, columns (yaw, pitch, roll, squeeze)
        jnp.stack([cn_delta, zero, zero, zero]),
        jnp.stack([zero, cn_delta, zero, zero]),
        jnp.stack([zero, zero, cl_delta, zero]),
        jnp.stack([zero, cm_delta, zero, zero]),
        jnp.stack([cm_delta, zero, zero, zero]),
    ])  # fmt: skip
    control = (b_u @ mixing).ravel()
    quadratic = (mixing.T @ jnp.diag(jnp.asarray(ca_u)) @ mixing).ravel()
    after_ca0 = jnp.concatenate([jnp.stack([cn_alpha, cm_alpha, zero, cn_q, cm_q, cy_r, cm_q, cl_p]), control, quadratic])
    ca0 = jnp.asarray(ca0, dtype=float)
    rows = jnp.concatenate([ca0[:, None], jnp.broadcast_to(after_ca0, (ca0.shape[0], after_ca0.shape[0]))], axis=1)
    names = linear_output_names(4)
    table = Table((jnp.asarray(ca0_mach, dtype=float),), rows, ("mach",), names)
    as_array = lambda x: jnp.asarray(x, dtype=float)  # noqa: E731
    return LinearAero(as_array(reference_area_m2), as_array(reference_length_m), as_array(moment_ref_x_m), table,
                      as_array(drag_scale), as_array(cl0), None, 4)  # fmt: skip


def linear_derivatives(aero: LinearAero, mach, altitude_m=0.0) -> dict[str, float]:
    """The simplified model's coefficients at one Mach number and altitude [m MSL], by name (per
    rad; the control derivatives per fin ``d<coefficient>/dd<i>``, and per virtual command
    ``<coefficient>_<yaw|pitch|roll>`` for four canards); host floats."""
    point = {"mach": mach, "altitude": altitude_m}
    values, _ = interpolate(aero.table, tuple(point[name] for name in aero.table.axis_names))
    out = {name: float(x) for name, x in zip(linear_output_names(aero.n_canards), np.asarray(values))}
    if aero.n_canards == 4:
        for command, unit in (("yaw", (1, 0, 0)), ("pitch", (0, 1, 0)), ("roll", (0, 0, 1))):
            delta = allocate(*unit)
            for c in CONTROL_OUTPUTS:
                out[f"{c}_{command}"] = sum(out[f"d{c}/dd{i + 1}"] * d for i, d in enumerate(delta))
    return out
