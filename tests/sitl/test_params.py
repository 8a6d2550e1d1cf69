"""Parameter protocol: list, read, set with types preserved; FTP NAKed; parameter files."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.sitl.client import Client
from uavtool.errors import ParamError
from uavtool.mavlink import mavlink as M
from uavtool.sitl import Sitl, SitlConfig
from uavtool.sitl.params import PARAM_SPECS, load_param_file

ARDUCOPTER_NAMES = (
    "SYSID_THISMAV",
    "SYSID_MYGCS",
    "FS_GCS_ENABLE",
    "FS_GCS_TIMEOUT",
    "ARMING_CHECK",
    "RTL_ALT",
    "WPNAV_SPEED",
    "WPNAV_ACCEL",
    "PILOT_SPEED_UP",
    "SIM_SPEEDUP",
    "SIM_WIND_SPD",
    "SIM_WIND_DIR",
)


def test_request_list_sends_every_parameter_with_index_and_count(client: Client) -> None:
    client.send(M.MAVLink_param_request_list_message(1, 1))
    client.wait_until(
        lambda c: sum(m.get_type() == "PARAM_VALUE" for m in c.received) >= len(PARAM_SPECS),
        timeout=10,
        what="all params",
    )
    values = [m for m in client.received if m.get_type() == "PARAM_VALUE"]
    assert {v.param_count for v in values} == {len(PARAM_SPECS)}
    assert sorted(v.param_index for v in values) == list(range(len(PARAM_SPECS)))
    names = {v.param_id for v in values}
    assert set(ARDUCOPTER_NAMES) <= names


def test_read_by_name_and_index(client: Client) -> None:
    client.send(M.MAVLink_param_request_read_message(1, 1, b"RTL_ALT", -1))
    v = client.wait_for("PARAM_VALUE")
    assert (v.param_id, v.param_value, v.param_type) == ("RTL_ALT", 1500.0, M.MAV_PARAM_TYPE_INT32)
    client.send(M.MAVLink_param_request_read_message(1, 1, b"", v.param_index))
    assert client.wait_for("PARAM_VALUE").param_id == "RTL_ALT"


@pytest.mark.parametrize(
    ("name", "sent", "mav_type", "expected"),
    [
        ("RTL_ALT", 2000.4, M.MAV_PARAM_TYPE_INT32, 2000.0),
        ("FS_GCS_ENABLE", 1, M.MAV_PARAM_TYPE_INT8, 1.0),
        ("WPNAV_SPEED", 750.3, M.MAV_PARAM_TYPE_REAL32, 750.2999877929688),
        ("FS_GCS_TIMEOUT", 2.5, M.MAV_PARAM_TYPE_REAL32, 2.5),
    ],
)
def test_set_echoes_type_and_stored_value(
    client: Client, name: str, sent: float, mav_type: int, expected: float
) -> None:
    client.send(M.MAVLink_param_set_message(1, 1, name.encode(), sent, mav_type))
    echo = client.wait_for("PARAM_VALUE", lambda m: m.param_id == name)
    assert echo.param_type == mav_type
    assert echo.param_value == expected
    client.send(M.MAVLink_param_request_read_message(1, 1, name.encode(), -1))
    assert client.wait_for("PARAM_VALUE", lambda m: m.param_id == name).param_value == expected


def test_unknown_parameter_set_is_refused_with_text(client: Client) -> None:
    client.send(M.MAVLink_param_set_message(1, 1, b"NO_SUCH_PARAM", 1, M.MAV_PARAM_TYPE_REAL32))
    assert "NO_SUCH_PARAM" in client.wait_for("STATUSTEXT").text
    assert not any(m.get_type() == "PARAM_VALUE" for m in client.received)


def test_wpnav_speed_changes_flight_speed(client: Client) -> None:
    client.send(M.MAVLink_param_set_message(1, 1, b"WPNAV_SPEED", 400, M.MAV_PARAM_TYPE_REAL32))
    client.wait_for("PARAM_VALUE")
    client.takeoff(5)
    client.send(
        M.MAVLink_set_position_target_local_ned_message(
            0, 1, 1, M.MAV_FRAME_LOCAL_NED, 0b110111111000, 60, 0, -5, 0, 0, 0, 0, 0, 0, 0, 0
        )
    )
    client.pump(4)
    assert max(
        m.groundspeed for m in client.received if m.get_type() == "VFR_HUD"
    ) == pytest.approx(4.0, rel=0.04)  # the vehicle catches up its target: a few % over


def test_ftp_is_nakked_at_once(client: Client) -> None:
    payload = bytearray(251)
    payload[0:2] = (7).to_bytes(2, "little")
    payload[3] = 4  # OpenFileRO
    payload[4] = 14
    payload[12:26] = b"@PARAM/param.pck"[:14]
    client.send(M.MAVLink_file_transfer_protocol_message(0, 1, 1, list(payload)))
    reply = bytes(client.wait_for("FILE_TRANSFER_PROTOCOL", timeout=2).payload)
    assert reply[3] == 129  # NAK
    assert reply[5] == 4  # to OpenFileRO
    assert int.from_bytes(reply[0:2], "little") == 8


def test_param_file_loaded_at_start(tmp_path: Path) -> None:
    f = tmp_path / "copter.parm"
    f.write_text("# saved by MAVProxy\nRTL_ALT 3000\nWPNAV_SPEED,800\n\nFS_GCS_ENABLE 1  # rtl\n")
    params = load_param_file(f)
    with Sitl(
        SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=20, params=tuple(params.items()))
    ) as sitl:
        c = Client.tcp(sitl.ports[0])
        c.send(M.MAVLink_param_request_read_message(1, 1, b"RTL_ALT", -1))
        assert c.wait_for("PARAM_VALUE").param_value == 3000
        c.close()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("RTL_ALT\n", "copter.parm:1: expected 'NAME VALUE'"),
        ("\nBOGUS 1\n", "copter.parm:2: unknown parameter 'BOGUS'"),
        ("LAND_SPEED -32768\n", "copter.parm:1: LAND_SPEED: -32768 out of range 30..200"),
    ],
)
def test_bad_param_file_names_file_and_line(tmp_path: Path, text: str, message: str) -> None:
    f = tmp_path / "copter.parm"
    f.write_text(text)
    with pytest.raises(ParamError, match=message):
        load_param_file(f)
