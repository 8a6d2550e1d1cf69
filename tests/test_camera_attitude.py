"""The camera pose from the whole attitude: a vehicle's heading (and, for a camera fixed to
the frame, its roll and pitch) composed with a gimbal's quaternion, never through Euler
angles where they are singular."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from uavtool.camera import CameraPose, Quaternion, camera_from_attitude

ORIGIN = (0.0, 0.0, 0.0)


def quat(roll_deg: float, pitch_deg: float, yaw_deg: float) -> Quaternion:
    """MAVLink's Z-Y-X quaternion (as ArduPilot builds it)."""
    r, p, y = (math.radians(a) / 2 for a in (roll_deg, pitch_deg, yaw_deg))
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    return (
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    )


def image_up_heading(pose: CameraPose) -> float:
    """The compass direction the top of a nadir image faces: minus the camera's down axis."""
    _, down, _ = pose.axes()
    return math.degrees(math.atan2(-down[0], -down[1])) % 360.0


def close_deg(a: float, b: float, tol: float = 1e-6) -> bool:
    return abs((a - b + 180.0) % 360.0 - 180.0) <= tol


def test_arducopters_nadir_quaternion_keeps_the_heading() -> None:
    """ArduCopter's servo mount at −90° with 0.13° of stabilising roll (issue 18): the
    image's top faces north within that roll, never 180° off."""
    q = (0.707106, -0.000787, -0.707106, -0.000787)
    pose = camera_from_attitude(
        ORIGIN, vehicle_heading_deg=0.0, gimbal_q=q, yaw_in_vehicle_frame=True
    )
    assert pose.pitch_deg == pytest.approx(-90.0, abs=0.2)
    assert close_deg(image_up_heading(pose), 0.0, tol=0.2)
    assert 0.0 <= pose.heading_deg < 360.0


@pytest.mark.parametrize("pitch_deg", [-90.0, -89.999, -89.9, -89.0, 89.0, 89.999, 90.0])
@pytest.mark.parametrize("vehicle_heading_deg", [0.0, 92.0, 169.0, 259.0, 359.99])
def test_at_and_near_90_pitch_the_heading_is_the_vehicles(
    pitch_deg: float, vehicle_heading_deg: float
) -> None:
    q = quat(0.0, pitch_deg, 0.0)
    pose = camera_from_attitude(
        ORIGIN, vehicle_heading_deg=vehicle_heading_deg, gimbal_q=q, yaw_in_vehicle_frame=True
    )
    assert close_deg(pose.heading_deg, vehicle_heading_deg)
    assert pose.pitch_deg == pytest.approx(pitch_deg, abs=1e-6)
    assert pose.roll_deg == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("roll_deg", [-5.0, 0.13, 3.0])
def test_roll_near_nadir_stays_roll(roll_deg: float) -> None:
    pose = camera_from_attitude(
        ORIGIN,
        vehicle_heading_deg=30.0,
        gimbal_q=quat(roll_deg, -89.5, 0.0),
        yaw_in_vehicle_frame=True,
    )
    assert pose.pitch_deg == pytest.approx(-89.5, abs=0.2)
    # at the nadir a roll turns the image like a heading would: the image's top follows
    assert close_deg(image_up_heading(pose), 30.0, tol=abs(roll_deg) + 0.6)


def test_yaw_in_vehicle_frame_adds_the_vehicle_heading() -> None:
    q = quat(0.0, -45.0, 40.0)
    pose = camera_from_attitude(
        ORIGIN, vehicle_heading_deg=350.0, gimbal_q=q, yaw_in_vehicle_frame=True
    )
    assert close_deg(pose.heading_deg, 30.0)  # wrapped
    assert pose.pitch_deg == pytest.approx(-45.0)


def test_yaw_in_earth_frame_ignores_the_vehicle_heading() -> None:
    q = quat(0.0, -45.0, 40.0)
    pose = camera_from_attitude(
        ORIGIN, vehicle_heading_deg=350.0, gimbal_q=q, yaw_in_vehicle_frame=False
    )
    assert close_deg(pose.heading_deg, 40.0)


def test_a_yaw_following_vehicle_turns_a_nadir_image() -> None:
    """ArduCopter faces its travel (headings 0/259/169/92 at the photo points, issue 18): a
    nadir photo's heading is the vehicle's, so the image is rotated by it."""
    for heading in (0.0, 259.0, 169.0, 92.0):
        pose = camera_from_attitude(
            ORIGIN,
            vehicle_heading_deg=heading,
            gimbal_q=quat(0.0, -90.0, 0.0),
            yaw_in_vehicle_frame=True,
        )
        assert close_deg(image_up_heading(pose), heading)


def test_a_camera_fixed_to_the_frame_tilts_with_the_vehicle() -> None:
    nadir = quat(0.0, -90.0, 0.0)
    pose = camera_from_attitude(
        ORIGIN,
        vehicle_heading_deg=0.0,
        gimbal_q=nadir,
        yaw_in_vehicle_frame=True,
        vehicle_pitch_deg=-10.0,  # nose down: the camera looks a little backwards
        stabilised=False,
    )
    _, _, forward = pose.axes()
    assert forward[1] == pytest.approx(-math.sin(math.radians(10.0)))
    assert forward[2] == pytest.approx(-math.cos(math.radians(10.0)))


def test_a_level_pose_keeps_its_old_axes_bit_for_bit() -> None:
    """Roll 0 takes the original formulas: poses recorded before rolls existed render and
    navigate exactly as they did."""
    h, p = math.radians(37.0), math.radians(-62.0)
    right, _, forward = CameraPose(ORIGIN, 37.0, -62.0).axes()
    assert forward == (math.sin(h) * math.cos(p), math.cos(h) * math.cos(p), math.sin(p))
    assert right == (math.cos(h), -math.sin(h), 0.0)


angles = st.floats(-179.0, 179.0)


@given(angles, st.floats(-90.0, 90.0), st.floats(-60.0, 60.0))
def test_from_axes_inverts_axes(heading: float, pitch: float, roll: float) -> None:
    pose = CameraPose(ORIGIN, heading % 360.0, pitch, roll)
    right, down, forward = pose.axes()
    back = CameraPose.from_axes(ORIGIN, right, forward)
    for a, b in zip(back.axes(), (right, down, forward), strict=True):
        assert a == pytest.approx(b, abs=1e-9)
    assert 0.0 <= back.heading_deg < 360.0


def test_a_quaternion_that_is_no_rotation_is_refused() -> None:
    from uavtool.errors import InputError

    with pytest.raises(InputError):
        camera_from_attitude(
            ORIGIN, vehicle_heading_deg=0.0, gimbal_q=(math.nan, 0, 0, 0), yaw_in_vehicle_frame=True
        )
