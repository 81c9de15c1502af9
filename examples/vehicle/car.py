"""car — the one table of the passenger car's parameters used by the vehicle FMU
(vehicle.py) and by run.py (static loads, cone-layout check).

Source of the published values (mass, yaw inertia, axle distances, track, height):
  "Adaptive Coordinated Path Tracking Control Strategy for Autonomous Vehicles
  with Direct Yaw Moment Control", Chinese Journal of Mechanical Engineering
  (SpringerOpen), Table 4 "The main vehicle parameters",
  https://doi.org/10.1186/s10033-021-00666-0
  (https://cjme.springeropen.com/articles/10.1186/s10033-021-00666-0/tables/4):
  m = 1610 kg, Iz = 2059.2 kg m^2, lf = 1.05 m, lr = 1.61 m, track 1.565 m,
  "height of the sprung mass from the roll center" h = 0.65 m.
The table gives no CG height above ground (its h = 0.65 m is measured from the roll
centre), so H_CG = 0.55 m is an ASSUMPTION: a typical sedan value (CG heights of
passenger cars lie around 0.5-0.6 m), it sets the load transfer when braking and
cornering. Wheel inertia, loaded wheel radius, brake capacity and the suspension
figures below are ASSUMPTIONS typical of a car on 205/60R15 wheels (the built-in
tyre of the FMU, Pacejka, *Tire and Vehicle Dynamics*, 3rd ed., App. 3).

Must never: hold a number twice (vehicle.py and run.py import it from here).
"""

G = 9.81  # m/s^2

MASS = 1610.0  # kg (CJME, doi 10.1186/s10033-021-00666-0, Table 4)
YAW_INERTIA = 2059.2  # kg m^2 (ibid.)
LF = 1.05  # m, CG to front axle (ibid.)
LR = 1.61  # m, CG to rear axle (ibid.)
TRACK = 1.565  # m, both axles (ibid.)
H_CG = 0.55  # m, CG height above ground (assumption, see header)

WHEELBASE = LF + LR
TYRE_WIDTH = 0.205  # m, 205/60R15
WIDTH = TRACK + TYRE_WIDTH  # m, outer tyre walls: the width b of ISO 3888-1's lanes

WHEEL_INERTIA = 1.0  # kg m^2, wheel + tyre + brake disc + half drive shaft (assumption)
WHEEL_RADIUS = 0.30  # m, loaded radius: lever of Fx about the axle (205/60R15 at ~4 kN)
BRAKE_MAX_FRONT = 2500.0  # N m per wheel (enough to lock a front wheel on dry road)
BRAKE_MAX_REAR = 1500.0  # N m per wheel
BRAKE_BUILD_UP = 0.05  # s, linear pressure build-up from brake onset
# Longitudinal compliance of each wheel centre in the suspension (wheel recession:
# bushings, and the body's pitch on its dampers seen at the hub), a Kelvin element
# between body and a massless hub. ASSUMPTION: 3e5 N/m (3.3 mm/kN, within the
# 1-5 mm/kN usual for passenger-car front suspensions) and a damping that makes the
# parked car's fore-aft mode on its tyres well damped (the tyres' own carcass damping
# is only ~2 % of critical for a quarter car).
RECESSION_STIFFNESS = 3.0e5  # N/m per wheel
RECESSION_DAMPING = 1.5e4  # N s/m per wheel
SUSPENSION_LAG = 0.05  # s, first-order lag of the quasi-static load transfer (pitch/roll)

# Wheel order everywhere: front-left, front-right, rear-left, rear-right.
WHEELS = ("fl", "fr", "rl", "rr")
# Wheel centre positions relative to the CG, ISO 8855 vehicle axes (x forward, y left).
POS_X = (LF, LF, -LR, -LR)
POS_Y = (TRACK / 2, -TRACK / 2, TRACK / 2, -TRACK / 2)
SIDE = ("left", "right", "left", "right")


def static_loads(grade=0.0):
    """Static normal loads (N) per wheel on a road of the given grade (rise/run),
    car level across; the grade's share of weight along the slope is carried by
    the tyres at ground level, so it moves h_cg*m*g*sin/L from one axle to the other
    (vehicle facing downhill for grade > 0: load moves to the front)."""
    import math

    th = math.atan(grade)
    w = MASS * G
    front = w * math.cos(th) * LR / WHEELBASE + w * math.sin(th) * H_CG / WHEELBASE
    rear = w * math.cos(th) - front
    return (front / 2, front / 2, rear / 2, rear / 2)
