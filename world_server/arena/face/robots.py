"""Robot models: body, wheel limits and sensors (sensors/: one module per sensor), as the papers give them.

Lengths in metres, angles in radians, speeds per second.  A bearing is counter-
clockwise from the robot's heading.  Where a paper gives a sensor's error as
"+-x" we read it as a uniform error within that bound; where it gives a
standard deviation (the DFT paper's position sensor) the error is normal.
Every number and where it comes from is in docs/arena.md.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from world_server.arena.face.sensors import Sensors
from world_server.arena.face.sensors.base import DEG
from world_server.arena.face.sensors.camera import Camera
from world_server.arena.face.sensors.compass import Compass
from world_server.arena.face.sensors.ir import IR
from world_server.arena.face.sensors.laser import Laser
from world_server.arena.face.sensors.odometry import Odometry
from world_server.arena.face.sensors.position import Position
from world_server.arena.face.sensors.sonar import Sonar


@dataclass(frozen=True)
class RobotModel:
    name: str
    radius: float
    axle: float  # distance between the wheels
    max_wheel_speed: float  # per wheel
    max_speed: float  # forward
    max_turn_rate: float
    colour: tuple[int, int, int] = (60, 60, 200)
    sensors: Sensors = field(default_factory=Sensors)

    def with_sensors(self, **changes) -> RobotModel:
        """This model with sensors added (a spec, or True for its defaults), replaced or left out (None)."""
        return replace(self, sensors=self.sensors.changed(**changes))


# Girard et al. (2005), section 3.2: 30 cm, 40 cm/s, 10 deg/s, a 36-sector camera,
# 8 sonars (5 m, +-5 deg, +-10 cm), encoders +-5%, compass +-10 deg.
ANIMAT = RobotModel(
    name="animat",
    radius=0.15,
    axle=0.25,
    max_wheel_speed=0.40,
    max_speed=0.40,
    max_turn_rate=10 * DEG,
    colour=(90, 90, 90),
    # one ray per 10-degree sector: the colour in each direction, the pixels the BG model counts
    # (a resource's angular size, so that 7 of them mean "within 70 cm": docs/bg.md)
    sensors=Sensors(camera=Camera(rays_per_sector=1), sonar=Sonar(), odometry=Odometry(), compass=Compass()),
)

# Distance from the e-puck's centre of each of ps0..ps7 (E-puck.proto's sensor translations: (0.030, 0.010),
# (0.022, 0.025), (0, 0.031), (0.030, 0.015), mirrored): the sensors sit 3.5-6 mm inside the 37 mm rim.
EPUCK_IR_MOUNTS = (0.0316, 0.0333, 0.0310, 0.0335, 0.0335, 0.0310, 0.0333, 0.0316)

# The e-puck of Billing et al. (2015) (Mondada et al. 2009): 74 mm, 53 mm axle,
# 12.9 cm/s per wheel, 8 IR proximity sensors, the noisy position sensor, a compass
# (the DFT robot reads its heading without noise: compass error 0).
EPUCK = RobotModel(
    name="epuck",
    radius=0.037,
    axle=0.053,
    max_wheel_speed=0.129,
    max_speed=0.129,
    max_turn_rate=2 * 0.129 / 0.053,
    colour=(40, 160, 40),
    sensors=Sensors(
        ir=IR(mounts=EPUCK_IR_MOUNTS), position=Position(), compass=Compass(error=0.0), odometry=Odometry(error=0.0)
    ),
)

# A mobile base with a 360-degree laser scanner and a panoramic colour camera
# (Tapus et al. 2006 used two back-to-back laser scanners and an omnidirectional camera),
# and a position sensor so a controller can drive a prescribed tour.
SCOUT = RobotModel(
    name="scout",
    radius=0.20,
    axle=0.33,
    max_wheel_speed=0.6,
    max_speed=0.6,
    max_turn_rate=90 * DEG,
    colour=(200, 120, 40),
    sensors=Sensors(
        camera=Camera(sectors=360, rays_per_sector=1),
        laser=Laser(beams=360, range=8.0),
        odometry=Odometry(),
        compass=Compass(error=2 * DEG),
        position=Position(),  # for driving a prescribed tour, as the paper's robot was driven; not a map input
    ),
)

MODELS = {m.name: m for m in (ANIMAT, EPUCK, SCOUT)}
