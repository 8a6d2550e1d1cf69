"""Mission protocol (MISSION_INT upload/download/clear, retries) and AUTO flight."""

from __future__ import annotations

import math

from tests.sitl.client import Client
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Sitl

REL = M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT


def _items(vehicle: Sitl) -> list[tuple[int, int, float, float, float, float, int, int, float]]:
    home = vehicle.config.home
    lat, lon = home.lat_e7, home.lon_e7
    return [
        (
            M.MAV_CMD_NAV_WAYPOINT,
            M.MAV_FRAME_GLOBAL_INT,
            0,
            0,
            0,
            0,
            lat,
            lon,
            home.alt_amsl_m,
        ),  # home
        (M.MAV_CMD_NAV_TAKEOFF, REL, 0, 0, 0, 0, 0, 0, 10),
        (M.MAV_CMD_DO_CHANGE_SPEED, M.MAV_FRAME_MISSION, 1, 5, -1, 0, 0, 0, 0),
        (M.MAV_CMD_NAV_WAYPOINT, REL, 0, 0, 0, 0, lat + 2000, lon, 12),
        (M.MAV_CMD_CONDITION_YAW, M.MAV_FRAME_MISSION, 90, 60, 1, 0, 0, 0, 0),
        (
            M.MAV_CMD_DO_MOUNT_CONTROL,
            M.MAV_FRAME_MISSION,
            -90,
            0,
            0,
            0,
            0,
            0,
            M.MAV_MOUNT_MODE_MAVLINK_TARGETING,
        ),
        (
            M.MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW,
            M.MAV_FRAME_MISSION,
            -45,
            0,
            math.nan,
            math.nan,
            0,
            0,
            0,
        ),
        (M.MAV_CMD_NAV_WAYPOINT, REL, 1, 0, 0, 0, lat + 2000, lon + 2000, 12),
        (M.MAV_CMD_NAV_LAND, REL, 0, 0, 0, 0, 0, 0, 0),
    ]


def _upload(client: Client, items: list, *, duplicate: bool = False) -> int:
    client.send(M.MAVLink_mission_count_message(1, 1, len(items), 0))
    while True:
        msg = client.wait_for("MISSION_REQUEST_INT", timeout=5) if True else None
        cmd, frame, p1, p2, p3, p4, x, y, z = items[msg.seq]
        item = M.MAVLink_mission_item_int_message(
            1, 1, msg.seq, frame, cmd, 0, 1, p1, p2, p3, p4, x, y, z, 0
        )
        client.send(item)
        if duplicate:
            client.send(item)
        if msg.seq == len(items) - 1:
            return int(client.wait_for("MISSION_ACK").type)


def _download(client: Client) -> list:
    client.send(M.MAVLink_mission_request_list_message(1, 1, 0))
    count = client.wait_for("MISSION_COUNT").count
    out = []
    for seq in range(count):
        client.send(M.MAVLink_mission_request_int_message(1, 1, seq, 0))
        out.append(client.wait_for("MISSION_ITEM_INT", lambda m, s=seq: m.seq == s))
    client.send(M.MAVLink_mission_ack_message(1, 1, 0, 0))
    return out


def test_upload_download_round_trip_with_home_at_zero(client: Client, vehicle: Sitl) -> None:
    items = _items(vehicle)
    assert _upload(client, items) == M.MAV_MISSION_ACCEPTED
    got = _download(client)
    assert len(got) == len(items)
    assert got[0].x == vehicle.config.home.lat_e7
    for item, msg in zip(items[1:], got[1:], strict=True):
        cmd, frame, p1, p2, _p3, _p4, x, y, z = item
        assert (msg.command, msg.frame, msg.param1, msg.param2, msg.x, msg.y, msg.z) == (
            cmd,
            frame,
            p1,
            p2,
            x,
            y,
            z,
        )


def test_duplicated_items_are_tolerated(client: Client, vehicle: Sitl) -> None:
    assert _upload(client, _items(vehicle), duplicate=True) == M.MAV_MISSION_ACCEPTED
    assert len(_download(client)) == len(_items(vehicle))


def test_lost_item_is_requested_again(client: Client, vehicle: Sitl) -> None:
    items = _items(vehicle)[:3]
    client.send(M.MAVLink_mission_count_message(1, 1, len(items), 0))
    first = client.wait_for("MISSION_REQUEST_INT")
    assert first.seq == 0
    again = client.wait_for("MISSION_REQUEST_INT", timeout=5)  # we never answered: it asks again
    assert again.seq == 0


def test_clear_and_empty_download_has_home_only(client: Client, vehicle: Sitl) -> None:
    _upload(client, _items(vehicle))
    client.send(M.MAVLink_mission_clear_all_message(1, 1, 0))
    assert client.wait_for("MISSION_ACK").type == M.MAV_MISSION_ACCEPTED
    assert len(_download(client)) == 1


def test_fence_and_rally_are_refused(client: Client) -> None:
    for mission_type in (M.MAV_MISSION_TYPE_FENCE, M.MAV_MISSION_TYPE_RALLY):
        client.send(M.MAVLink_mission_count_message(1, 1, 3, mission_type))
        ack = client.wait_for("MISSION_ACK")
        assert (ack.type, ack.mission_type) == (M.MAV_MISSION_UNSUPPORTED, mission_type)
        client.send(M.MAVLink_mission_request_list_message(1, 1, mission_type))
        assert client.wait_for("MISSION_ACK").type == M.MAV_MISSION_UNSUPPORTED


def test_unsupported_item_command_is_refused(client: Client, vehicle: Sitl) -> None:
    items = [
        *_items(vehicle)[:2],
        (M.MAV_CMD_DO_SET_SERVO, M.MAV_FRAME_MISSION, 0, 0, 0, 0, 0, 0, 0),
    ]
    assert _upload(client, items) == M.MAV_MISSION_UNSUPPORTED


def test_auto_flight_reports_progress_and_lands(client: Client, vehicle: Sitl) -> None:
    assert _upload(client, _items(vehicle)) == M.MAV_MISSION_ACCEPTED
    client.set_mode("GUIDED")
    assert client.command(M.MAV_CMD_COMPONENT_ARM_DISARM, 1).result == M.MAV_RESULT_ACCEPTED
    assert client.command(M.MAV_CMD_MISSION_START, 0, 0).result == M.MAV_RESULT_ACCEPTED
    client.wait_for("HEARTBEAT", lambda m: m.custom_mode == 3)
    client.wait_until(
        lambda c: not c.latest["HEARTBEAT"].base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED,
        timeout=60,
        what="mission end",
    )
    reached = [m.seq for m in client.received if m.get_type() == "MISSION_ITEM_REACHED"]
    assert reached == list(range(1, 9))
    currents = [m.seq for m in client.received if m.get_type() == "MISSION_CURRENT"]
    assert {1, 3, 7, 8} <= set(currents)
    assert client.alt_m() < 0.05
    # The last waypoint was ~22 m north and east of home: it landed there.
    pos = client.latest["GLOBAL_POSITION_INT"]
    assert abs(pos.lat - (vehicle.config.home.lat_e7 + 2000)) < 30


def test_set_mission_current(client: Client, vehicle: Sitl) -> None:
    _upload(client, _items(vehicle))
    assert client.command(M.MAV_CMD_DO_SET_MISSION_CURRENT, 3).result == M.MAV_RESULT_ACCEPTED
    assert client.wait_for("MISSION_CURRENT", lambda m: m.seq == 3).total == 8
    assert client.command(M.MAV_CMD_DO_SET_MISSION_CURRENT, 42).result == M.MAV_RESULT_DENIED
