"""Splitting a byte stream into MAVLink frames, robustly, keeping each frame's exact bytes.

pymavlink's own parser drops a whole claimed frame length when a CRC fails, so one
corrupt length byte can swallow the good frames behind it. ``FrameParser`` resynchronises
like the reference C library instead: on any bad frame it skips one byte and looks for the
next start marker. Every accepted frame keeps its exact bytes (for lossless recording).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from uavtool.mavlink.dialect import mavlink
from uavtool.mavlink.payload import frame_crc, layout, values

_STX_V1 = 0xFE
_STX_V2 = 0xFD
_SIGNED = mavlink.MAVLINK_IFLAG_SIGNED
# Seconds between the Unix epoch and MAVLink signing's epoch (2015-01-01).
_SIGNING_EPOCH_S = 1420070400
_MAX_BUFFER = 1 << 20


@dataclass(frozen=True, slots=True)
class Frame:
    """One decoded MAVLink frame: the pymavlink message and its exact wire bytes."""

    msg: Any  # a pymavlink MAVLink_message subclass
    raw: bytes
    signed: bool


class FrameParser:
    """Incremental, resynchronising MAVLink 1/2 frame parser.

    ``signing_key`` (32 bytes) enables signature checks: ``Frame.signed`` is True only
    for frames whose signature verified; unsigned frames are still returned (the caller
    decides what to accept, as ArduPilot does).
    """

    def __init__(self, *, signing_key: bytes | None = None) -> None:
        self._mav = mavlink.MAVLink(None)
        self._mav.robust_parsing = True
        if signing_key is not None:
            self._mav.signing.secret_key = signing_key
            self._mav.signing.allow_unsigned_callback = lambda _mav, _msg_id: True
        self._buf = bytearray()
        self.frames_ok = 0
        self.bytes_dropped = 0
        self.unknown_ids = 0

    def feed(self, data: bytes) -> list[Frame]:
        """Add received bytes; return every complete, valid frame now available."""
        buf = self._buf
        buf += data
        out: list[Frame] = []
        pos = 0
        n = len(buf)
        while pos < n:
            stx = buf[pos]
            if stx not in (_STX_V2, _STX_V1):
                nxt = _next_stx(buf, pos + 1)
                self.bytes_dropped += nxt - pos
                pos = nxt
                continue
            if stx == _STX_V2:
                if n - pos < 3:
                    break
                flen = 12 + buf[pos + 1] + (13 if buf[pos + 2] & _SIGNED else 0)
            else:
                if n - pos < 2:
                    break
                flen = 8 + buf[pos + 1]
            if n - pos < flen:
                break
            raw = bytes(buf[pos : pos + flen])
            frame = self._decode(raw)
            if frame is None:  # bad CRC, bad flags or unknown id: resync one byte on
                self.bytes_dropped += 1
                pos += 1
                continue
            out.append(frame)
            pos += flen
        del buf[:pos]
        if len(buf) > _MAX_BUFFER:  # never reached by valid traffic (frames are < 300 bytes)
            self.bytes_dropped += len(buf)
            buf.clear()
        return out

    def _decode(self, raw: bytes) -> Frame | None:
        if raw[0] == _STX_V2 and raw[2] & ~_SIGNED:
            return None  # unknown incompatibility flag: must not be parsed
        msg = self._decode_unsigned(raw)
        if msg is _UNSURE:
            try:
                msg = self._mav.decode(bytearray(raw))
            except (mavlink.MAVError, ValueError, IndexError, TypeError):
                return None
        elif msg is None:
            return None
        if isinstance(msg, mavlink.MAVLink_unknown):
            self.unknown_ids += 1
            return None
        self.frames_ok += 1
        return Frame(msg, raw, bool(getattr(msg, "_signed", False)))

    def _decode_unsigned(self, raw: bytes) -> Any:
        """The message pymavlink's ``decode`` makes of an unsigned MAVLink 2 frame of a known
        type, built as it builds it (the type's constructor, then the same attributes), at
        half its cost (`payload`); None for a bad CRC, which pymavlink refuses; `_UNSURE`
        for every other frame (signed, MAVLink 1, a parser with a signing key, CRC checks
        turned off, a length that does not add up), which pymavlink then decodes."""
        n = len(raw)
        if raw[0] != _STX_V2 or raw[2] or raw[1] != n - 12:
            return _UNSURE
        if self._mav.signing.secret_key is not None:  # pymavlink counts unsigned frames
            return _UNSURE
        msgid = raw[7] | raw[8] << 8 | raw[9] << 16
        cls = mavlink.mavlink_map.get(msgid)
        if cls is None:
            return _UNSURE
        lay = layout(cls)
        crc = raw[-2] | raw[-1] << 8
        if crc != _crc16(raw[1:-2] + lay.crc_extra):
            return _UNSURE if mavlink.MAVLINK_IGNORE_CRC else None
        try:
            msg = cls(*values(lay, raw[10:-2]))
        except Exception:  # whatever it is, pymavlink's decode says what
            return _UNSURE
        buf = bytearray(raw)
        msg._signed = False
        msg._msgbuf = buf
        msg._payload = buf[6:-2]
        msg._crc = crc
        msg._header = mavlink.MAVLink_header(msgid, 0, raw[3], raw[1], raw[4], raw[5], raw[6])
        return msg


_UNSURE = object()  # FrameParser._decode_unsigned: pymavlink decides
_crc16 = frame_crc(mavlink)


def _next_stx(buf: bytearray, start: int) -> int:
    a = buf.find(_STX_V2, start)
    b = buf.find(_STX_V1, start)
    if a < 0:
        return len(buf) if b < 0 else b
    return a if b < 0 else min(a, b)


def new_encoder(
    *, sysid: int, compid: int, signing_key: bytes | None = None, link_id: int = 0
) -> Any:
    """A pymavlink ``MAVLink`` object that packs messages from ``sysid``/``compid``.

    With ``signing_key`` every packed frame is signed; the signing timestamp starts at the
    current wall time, as the MAVLink signing spec requires.
    """
    mav = mavlink.MAVLink(None, srcSystem=sysid, srcComponent=compid)
    if signing_key is not None:
        mav.signing.secret_key = signing_key
        mav.signing.sign_outgoing = True
        mav.signing.link_id = link_id
        mav.signing.timestamp = int((time.time() - _SIGNING_EPOCH_S) * 100_000)
    return mav
