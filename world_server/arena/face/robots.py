"""Robot models: body, wheel limits and sensor suite, as the papers give them.

Lengths in metres, angles in radians, speeds per second.  A bearing is counter-
clockwise from the robot's heading.  Where a paper gives a sensor's error as
"+-x" we read it as a uniform error within that bound; where it gives a
standard deviation (the DFT paper's position sensor) the error is normal.
Every number and where it comes from is in docs/arena.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

DEG = math.pi / 180.0
# IR response: reading against distance from the sensor (m), piecewise linear, 0 when the
# ray meets nothing within range.  The shape of the e-puck calibration curves Webots
# uses (4095 at contact, about 67 at 7 cm); the DFT controller only uses log(1 + p/50).
IR_DISTANCE = np.array([0.0, 0.005, 0.01, 0.015, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07])
IR_VALUE = np.array([4095.0, 2133.0, 1465.0, 601.0, 383.0, 234.0, 158.0, 120.0, 104.0, 67.0])
SENSOR_KINDS = ("camera", "sonar", "ir", "laser", "odometry", "compass", "position", "contact", "zones")
# The `zones` reading is a bit field: bit k set when the robot is in a zone of kind ZONE_KINDS[k].
ZONE_KINDS = ("goal", "ingesting", "digesting", "dangerous", "start", "place")


@dataclass(frozen=True)
class Camera:
    """Panoramic linear camera: per sector the colour, grey level and distance
    of the nearest wall or robot among `rays_per_sector` rays spread over it."""

    sectors: int = 36
    rays_per_sector: int = 5
    range: float = 30.0


@dataclass(frozen=True)
class Sonar:
    """Ring of sonars; each is a cone of `cone_rays` rays over `beam_width`
    reporting its nearest echo, with a bearing error (the whole cone turns)
    and a distance error, both uniform within their bounds."""

    count: int = 8
    range: float = 5.0
    beam_width: float = 15 * DEG
    cone_rays: int = 3
    bearing_error: float = 5 * DEG
    range_error: float = 0.10


@dataclass(frozen=True)
class IR:
    """Infrared proximity sensors looking out from the robot: a reading from the
    documented response curve of the distance from the sensor (docs/arena.md)."""

    bearings: tuple[float, ...] = (-0.30, -0.80, -1.57, -2.64, 2.64, 1.57, 0.80, 0.30)  # e-puck ps0..ps7
    range: float = 0.07
    # How far each sensor sits from the robot's centre (m); None: on the rim.  Distances are measured
    # from the sensor, as Webots measures them, so a sensor inside the body reads a touching wall as
    # (rim - mount) away, not as 0.
    mounts: tuple[float, ...] | None = None
    noise: float = 0.0  # relative std of a reading
    # Webots' infra-red model (the DFT paper's simulator): a surface reflects by f = 0.2 + 0.8 * red level,
    # and the sensor reads the curve at d + (d / f - d) * red_sensitivity (Webots' redColorSensitivity,
    # default 1): a dark or non-red surface seems farther.  0 reads the curve at the true distance.
    red_sensitivity: float = 1.0


@dataclass(frozen=True)
class Laser:
    beams: int = 64
    fov: float = 2 * math.pi
    range: float = 8.0
    noise: float = 0.01  # std, metres


@dataclass(frozen=True)
class Odometry:
    """Distance and turn since the last control period, each off by a uniform
    relative error within `error` (the BG paper's +-5% of the distance)."""

    error: float = 0.05


@dataclass(frozen=True)
class Compass:
    error: float = 10 * DEG  # uniform within +-error


@dataclass(frozen=True)
class Position:
    """Noisy position sensor (the DFT paper's): normal error per axis; the
    scenario's noise level sets its std (none 0, low 5 mm, high 20 mm)."""

    std: float | None = None  # None: from the noise level


@dataclass(frozen=True)
class Sensors:
    camera: Camera | None = None
    sonar: Sonar | None = None
    ir: IR | None = None
    laser: Laser | None = None
    odometry: Odometry | None = None
    compass: Compass | None = None
    position: Position | None = None
    contact: bool = True
    zones: bool = True

    def names(self) -> list[str]:
        return [k for k in SENSOR_KINDS if getattr(self, k)]


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
        return replace(self, sensors=replace(self.sensors, **changes))

    def ir_mounts(self) -> np.ndarray:
        """Each IR sensor's distance from the centre, where its range is measured from (ValueError if unusable)."""
        ir = self.sensors.ir
        if ir is None:
            return np.zeros(0)
        if ir.mounts is None:
            return np.full(len(ir.bearings), self.radius)
        mounts = np.asarray(ir.mounts, np.float64)
        if mounts.shape != (len(ir.bearings),) or not np.all((mounts > 0) & (mounts <= self.radius)):
            raise ValueError(f"ir.mounts: give one distance in (0, radius = {self.radius}] per bearing "
                             f"({len(ir.bearings)}), or leave it out for sensors on the rim")  # fmt: skip
        return mounts


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
