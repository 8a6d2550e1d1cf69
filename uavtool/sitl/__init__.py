"""The built-in SITL vehicle: an ArduCopter-like multicopter that speaks MAVLink 2.

Run it from the shell with ``uavtool sitl`` or in-process::

    from uavtool.sitl import Sitl, SitlConfig
    with Sitl(SitlConfig(endpoints=("tcpin:127.0.0.1:0",), speedup=10)) as sitl:
        ...  # connect any MAVLink client to sitl.ports[0]
"""

from uavtool.sitl.config import SitlConfig, parse_home, parse_signing_key
from uavtool.sitl.obstacles import Prism
from uavtool.sitl.server import Sitl
from uavtool.sitl.state import Mode

__all__ = ["Mode", "Prism", "Sitl", "SitlConfig", "parse_home", "parse_signing_key"]
