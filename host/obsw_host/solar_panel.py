"""A sample component, the solar panel: an angle, set_angle, deploy and two events.

A plug-in component (``obsw_host.obc.plugins``): a mission names it as
``"components": {"SolarPanel": {"module": "obsw_host.solar_panel"}}``; the module gives the
interface ``SOLAR_PANEL`` (named "SolarPanel") and the class ``SolarPanel``. Run it in its
own process with ``obsw il serve obsw_host.solar_panel`` (or ``python -m
obsw_host.solar_panel [--dir DIR]``); other processes use it through a proxy built from
``SOLAR_PANEL``. SIGTERM or SIGINT stop it cleanly (its name is withdrawn).
"""

import sys

from obsw.il.errors import ComponentError
from obsw.il.interface import CONFIGURATION, DATA, INFO, Attribute, Event, Interface, Operation

SOLAR_PANEL = Interface(
    "SolarPanel",
    0x50,
    [
        Attribute("angle", 1, DATA, type="f32", unit="deg", description="hinge angle"),
        Attribute("speed", 2, CONFIGURATION, type="f32", unit="deg/s", description="slew rate"),
        Attribute("is_deployed", 3, DATA, type="bool"),
        Operation("set_angle", 4, ("angle",), returns="f32", description="turn to an angle"),
        Operation("deploy", 5, (), asynchronous=True, description="release and unfold"),
        Event("angle_reached", 6, INFO, fields=("angle",)),
        Event("deployed", 7, INFO, fields=("hinges",)),
    ],
    description="a deployable, rotatable solar panel",
)

ANGLE_LIMIT = 90.0


class SolarPanel:
    """The panel's implementation (simulated hardware)."""

    def __init__(self):
        self.angle = 0.0
        self._speed = 5.0
        self.is_deployed = False
        self.il = None

    def il_bind(self, provider):
        self.il = provider

    @property
    def speed(self):
        return self._speed

    @speed.setter
    def speed(self, value):
        if not 0 < value <= 20:
            raise ValueError("speed must be in (0, 20] deg/s", value)
        self._speed = float(value)

    def set_angle(self, angle):
        if not self.is_deployed:
            raise ComponentError("NOT_DEPLOYED", "deploy the panel before turning it")
        if not -ANGLE_LIMIT <= angle <= ANGLE_LIMIT:
            raise ComponentError(
                "ANGLE_OUT_OF_RANGE",
                "angle %s beyond the hinge limit" % angle,
                {"angle": angle, "limit": ANGLE_LIMIT},
            )
        self.il.update("angle", float(angle))
        self.il.emit("angle_reached", {"angle": float(angle)})
        return self.angle

    def deploy(self, job):
        if self.is_deployed:
            job.succeed("already deployed")
            return
        for hinge in (1, 2, 3):  # the simulated release of three hinges, one after another
            job.update({"hinge": hinge, "of": 3})
        self.il.update("is_deployed", True)
        self.il.emit("deployed", {"hinges": 3})
        job.succeed("deployed")


def main(argv=None):
    """``python -m obsw_host.solar_panel [--dir DIR] [--quiet]``: serve the panel."""
    from obsw_host.obc.plugins import main as serve_main

    return serve_main([__name__] + list(sys.argv[1:] if argv is None else argv))


if __name__ == "__main__":
    sys.exit(main())
