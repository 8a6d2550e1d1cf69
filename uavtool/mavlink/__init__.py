"""MAVLink 2 (ardupilotmega dialect) plumbing shared by the SITL vehicle and the client link.

The dialect is chosen explicitly by importing pymavlink's generated module; nothing here
touches environment variables or pymavlink's ``mavutil`` globals.
"""

from uavtool.mavlink.dialect import DIALECT, mavlink
from uavtool.mavlink.framing import Frame, FrameParser, new_encoder

__all__ = ["DIALECT", "Frame", "FrameParser", "mavlink", "new_encoder"]
