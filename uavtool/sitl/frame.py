"""The airframe: what a multicopter's motors, propellers and body can do in the air.

A frame is described the way ArduPilot's SITL describes one (its ``SIM_Frame`` model): the
mass, the throttle it hovers at, one measured flight at a steady lean angle and speed (which
fixes its drag), and the electrical power it draws in the hover (which fixes its current). The
defaults are that model's own numbers (a 3 kg quadcopter on a 3S battery), so that the built-in
vehicle and ArduCopter's SITL fly the same airframe and can be compared manoeuvre by manoeuvre
(``benchmarks/bench_dynamics.py``).

:func:`airframe` turns a description into the constants the physics step uses, at the air
density of the vehicle's home: thrust scales with the air's density, so a vehicle at altitude
hovers at a higher throttle and has less thrust to spare.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

GRAVITY_MSS = 9.80665
SEA_LEVEL_DENSITY_KGM3 = 1.225


def air_density_kgm3(alt_amsl_m: float) -> float:
    """The International Standard Atmosphere's density at ``alt_amsl_m`` (troposphere)."""
    alt = min(max(alt_amsl_m, -1000.0), 11000.0)
    return SEA_LEVEL_DENSITY_KGM3 * math.pow(1.0 - 2.25577e-5 * alt, 4.2559)


@dataclass(frozen=True, slots=True)
class Frame:
    """A multicopter as measured: SI units, angles in degrees."""

    mass_kg: float = 3.0
    motors: int = 4
    hover_throttle: float = 0.39
    """Throttle (0-1, thrust-linearised, ArduCopter's MOT_THST_HOVER) that holds the hover at
    ``ref_alt_m``: the maximum thrust is the hover thrust over this."""
    ref_speed_ms: float = 15.08
    ref_angle_deg: float = 45.0
    """A steady level flight at ``ref_speed_ms`` needed this lean angle: the drag at that
    speed is the weight times tan(angle)."""
    ref_alt_m: float = 593.0
    """Altitude above sea level of the reference flights (their air density)."""
    hover_current_a: float = 29.3
    hover_voltage_v: float = 12.09
    """The battery's current and voltage in the hover: the power per newton of thrust."""
    disc_area_m2: float = 0.385
    """The propellers' disc area, all together."""
    momentum_drag_coef: float = 0.2
    """Share of the drag that grows with airspeed times the root of the thrust (the
    propellers turning the air they meet), against drag that grows with airspeed squared."""
    motor_time_constant_s: float = 0.05
    """First-order lag of the motors' thrust behind their command."""
    battery_full_v: float = 12.6
    """A full 3S LiPo (ArduPilot SITL's SIM_BATT_VOLTAGE)."""


@dataclass(frozen=True, slots=True)
class Airframe:
    """A :class:`Frame` as the physics step uses it, at one air density (SI units)."""

    mass_kg: float
    weight_n: float
    thrust_max_n: float
    drag_area_n_per_ms2: float
    """Quadratic drag: force = this × airspeed² (½ ρ Cd A)."""
    momentum_drag: float
    """Momentum drag: force = this × airspeed × √thrust."""
    inflow_area_n_per_ms2: float
    """Thrust lost to air flowing into the propellers: this × inflow speed² (½ ρ A_eff)."""
    watts_per_newton: float
    motor_time_constant_s: float
    battery_full_v: float


def airframe(frame: Frame, *, density_kgm3: float) -> Airframe:
    """The constants of ``frame`` at ``density_kgm3``. Raises ValueError for a frame whose
    numbers cannot fly (non-positive mass, a hover throttle outside (0, 1], …)."""
    if not (
        0.0 < frame.mass_kg < math.inf
        and 0.0 < frame.hover_throttle <= 1.0
        and 0.0 < frame.ref_speed_ms < math.inf
        and 0.0 < frame.ref_angle_deg < 90.0
        and frame.motors > 0
        and frame.disc_area_m2 > 0.0
        and frame.hover_current_a > 0.0
        and frame.hover_voltage_v > 0.0
        and frame.momentum_drag_coef >= 0.0
        and frame.motor_time_constant_s >= 0.0
        and 0.0 < density_kgm3 < math.inf
    ):
        raise ValueError(f"frame {frame} cannot fly")
    ref_density = air_density_kgm3(frame.ref_alt_m)
    weight = frame.mass_kg * GRAVITY_MSS
    # Drag from the reference flight: at its lean, thrust balances weight and drag. The air
    # meets the tilted rotor plane at speed × cos(lean); the momentum drag it makes there pulls
    # horizontally with cos(lean) of its strength (ArduPilot's SITL calibrates its frames so).
    tilt = math.radians(frame.ref_angle_deg)
    drag_at_ref = weight * math.tan(tilt)
    thrust_at_ref = weight / math.cos(tilt)
    airspeed = frame.ref_speed_ms
    momentum_coef = frame.momentum_drag_coef
    momentum_at_ref = (
        math.cos(tilt)
        * momentum_coef
        * airspeed
        * math.cos(tilt)
        * math.sqrt(thrust_at_ref * ref_density * frame.disc_area_m2)
    )
    if momentum_at_ref > drag_at_ref:  # the rotor alone explains the drag
        momentum_coef *= drag_at_ref / momentum_at_ref
        momentum_at_ref = drag_at_ref
    area_cd = (drag_at_ref - momentum_at_ref) / (0.5 * ref_density * airspeed * airspeed)
    # Thrust is proportional to the air's density at a given throttle.
    hover_thrust_ref = weight
    thrust_max = hover_thrust_ref / frame.hover_throttle * density_kgm3 / ref_density
    # The hover's induced velocity (from its power) gives the propellers' effective area.
    power = frame.hover_current_a * frame.hover_voltage_v
    outflow_ms = 2.0 * power / weight
    effective_area = weight / (0.5 * ref_density * outflow_ms * outflow_ms)
    return Airframe(
        mass_kg=frame.mass_kg,
        weight_n=weight,
        thrust_max_n=thrust_max,
        drag_area_n_per_ms2=0.5 * density_kgm3 * area_cd,
        momentum_drag=momentum_coef * math.sqrt(density_kgm3 * frame.disc_area_m2),
        inflow_area_n_per_ms2=0.5 * density_kgm3 * effective_area,
        watts_per_newton=power / weight,
        motor_time_constant_s=frame.motor_time_constant_s,
        battery_full_v=frame.battery_full_v,
    )
