"""vehicle — a two-track passenger car as an FMI 2.0 co-simulation FMU, authored in
Python and exported with pythonfmu (`pythonfmu build -f vehicle.py car.py iso3888.py`):
the "vehicle model from another tool" of issue 17, coupled to four TyreKit FMUs.

Model (ISO 8855 vehicle axes: x forward, y left, z up; SI units):
- planar body: position X, Y, yaw psi; body velocities u, v; yaw rate r. Newton-Euler
  in the moving frame, m(u' - v r) = sum Fx_b + m g sin(theta) (grade, car facing
  downhill), m(v' + u r) = sum Fy_b, Iz r' = sum(x_i Fy_b,i - y_i Fx_b,i) + sum Mz_i
  (the textbook planar vehicle model, e.g. Pacejka, *Tire and Vehicle Dynamics*,
  3rd ed., ch. 1, there for one track; here with the four wheels' positions);
- four wheel-spin degrees of freedom, Iw omega' = My - Rw Fx + Td - Tb sign(omega),
  the brake as a Coulomb friction torque that holds a stopped wheel (stick-slip as in
  tyrekit's transient/scenario.rs);
- normal loads: static axle shares plus quasi-static load transfer from the tyre
  forces at ground level, dFz_front = -h sum Fx / L (pitch), dFz_left = -h sum Fy / t
  per axle in proportion to the static axle loads (roll), both through a first-order
  lag SUSPENSION_LAG (pitch and roll of the sprung mass are not modelled). The tyre
  forces already contain m a plus the grade's weight component, so one formula holds
  when braking, cornering and parked on a slope;
- wheel recession: each wheel centre sits on a longitudinal spring-damper to the
  body (massless hub, car.RECESSION_*), so the hub's fore-aft speed, not the body's,
  reaches the tyre; this is what damps the parked car's fore-aft mode on its tyres;
- front-wheel steering (both front wheels at the driver's angle delta); wheel-centre
  velocities u - r y_i, v + r x_i rotated by -delta into each wheel's ISO-W frame;
- brakes: linear build-up over BRAKE_BUILD_UP from `t_brake`, an ABS slip controller
  per wheel that holds the estimated slip at `abs_slip` (wheel torque balance plus a
  proportional term with a 20 ms time constant) above `abs_off_speed`, below which the
  brakes apply fully and hold the stopped car (ABS units switch off near standstill);
- driver for `lane-change`: a Stanley path follower with curvature feed-forward
  (see `_steer`) on the ISO 3888-1 reference path, and a proportional speed
  controller on the rear-wheel drive torque.

Semi-implicit Euler over each communication step with the tyre forces held (the
co-simulation's zero-order hold). Inputs: the four tyres' Fx, Fy, Mz, My (ISO-W at each
wheel). Outputs per wheel: vx, vy, omega, Fz, gamma; body states for the trace.

Must never: read tyre properties (it sees only the forces the tyre FMUs send); use
the master's clock for decisions (it counts its own steps, so every master that
sends the same step sizes gets the same braking onset).
"""

import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real, String

import car
import iso3888

SCENARIOS = ("abs", "lane-change", "slope", "coast")
# output names per wheel, built once (the step runs at 1 kHz in Python)
_OUT = tuple(tuple(f"{q}_{w}" for q in ("vx", "vy", "omega", "Fz", "gamma", "Tb")) for w in car.WHEELS)


class Vehicle(Fmi2Slave):
    author = "tyrekit"
    description = "Two-track passenger car with ABS brakes and a path-following driver (ISO 8855 axes)"

    # name -> default of the tunable parameters (all SI)
    PARAMS = {
        "v0": 100.0 / 3.6,  # initial speed (m/s)
        "x0": 0.0,  # initial X of the CG (m)
        "grade": 0.0,  # road grade rise/run, > 0 = downhill in the driving direction
        "t_brake": 0.2,  # brake onset (s)
        "abs_slip": 0.1,  # slip the ABS holds (magnitude, estimated with rolling_radius)
        "abs_off_speed": 1.5,  # below this speed (m/s) the brakes apply fully
        "rolling_radius": 0.305,  # free-rolling radius (m): initial spin and ABS slip estimate
        "preview": 0.2,  # driver: curvature feed-forward preview (s)
        "steer_gain": 0.75,  # driver: cross-track gain k (1/s)
        "speed_gain": 1.0,  # speed controller gain (1/s)
    }

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.scenario = "abs"
        for k, v in self.PARAMS.items():
            setattr(self, k, v)
        self._reset()
        self.register_variable(
            String("scenario", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable,
                   setter=lambda v: self._set_param("scenario", v),
                   description="abs | lane-change | slope | coast")
        )
        for k in self.PARAMS:
            self.register_variable(
                Real(k, causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable,
                     setter=lambda v, k=k: self._set_param(k, v))
            )
        for w in car.WHEELS:
            for q in ("Fx", "Fy", "Mz", "My"):
                setattr(self, f"{q}_{w}", 0.0)
                self.register_variable(Real(f"{q}_{w}", causality=Fmi2Causality.input))
        for w in car.WHEELS:
            for q in ("vx", "vy", "omega", "Fz", "gamma"):
                self.register_variable(Real(f"{q}_{w}", causality=Fmi2Causality.output))
        for w in car.WHEELS:
            self.register_variable(Real(f"Tb_{w}", causality=Fmi2Causality.output))
        for q in ("x", "y", "psi", "vx", "vy", "yaw_rate", "ax", "ay", "delta", "time"):
            self.register_variable(Real(q, causality=Fmi2Causality.output))
        # Real value reference -> attribute name (every Real reads as an attribute;
        # inputs are written as attributes, parameters through _set_param)
        self._real_names = {vr: v.name for vr, v in self.vars.items() if isinstance(v, Real)}
        self._real_inputs = {vr: v.name for vr, v in self.vars.items()
                             if isinstance(v, Real) and v.causality == Fmi2Causality.input}

    # pythonfmu's get_real/set_real call a lambda per value and type-check each one;
    # at 1 kHz with 16 inputs and 20 outputs that was a third of the FMU's cost.
    def get_real(self, vrs):
        names = self._real_names
        try:
            return [getattr(self, names[vr]) for vr in vrs]
        except KeyError as e:
            raise TypeError(f"Variable with valueReference={e.args[0]} is not of type Real!") from None

    def set_real(self, vrs, values):
        inputs = self._real_inputs
        for vr, value in zip(vrs, values):
            name = inputs.get(vr)
            if name is not None:
                setattr(self, name, value)
            elif vr in self._real_names:
                self._set_param(self._real_names[vr], value)
            else:
                raise TypeError(f"Variable with valueReference={vr} is not of type Real!")

    # ------------------------------------------------------------------ set-up

    def _set_param(self, name, value):
        if name == "scenario" and value not in SCENARIOS:
            raise ValueError(f"scenario must be one of {SCENARIOS}, got {value!r}")
        setattr(self, name, value)
        if self._steps == 0:
            self._reset()

    def _reset(self):
        """State and outputs at t = 0 from the parameters (called again whenever a
        parameter is set before the first step)."""
        self._steps = 0
        self._th = math.atan(self.grade)
        self.x, self.y, self.psi = self.x0, 0.0, 0.0
        self.vx, self.vy, self.yaw_rate = self.v0, 0.0, 0.0
        self.ax = self.ay = self.delta = self.time = 0.0
        self._omega = [self.v0 / self.rolling_radius] * 4
        self._tb = [0.0] * 4
        self._xi = [0.0] * 4  # wheel-centre recession (m, + = forward of design)
        self._xidot = [0.0] * 4
        self._vxw = [0.0] * 4  # wheel-frame vx sent to the tyres (the ABS reads it)
        # filtered tyre force sums (N) for the load transfer: start at the static state
        self._sfx = 0.0
        self._sfy = 0.0
        self._outputs()

    def _outputs(self):
        """Per-wheel outputs from the current state (no step)."""
        c, s = math.cos(self.delta), math.sin(self.delta)
        w = car.MASS * car.G * math.cos(self._th)
        L, h, t = car.WHEELBASE, car.H_CG, car.TRACK
        dpitch = -h * self._sfx / L / 2  # per front wheel
        droll = h * self._sfy / t  # total left-to-right transfer
        fz = (
            w * car.LR / L / 2 + dpitch - droll * car.LR / L,
            w * car.LR / L / 2 + dpitch + droll * car.LR / L,
            w * car.LF / L / 2 - dpitch - droll * car.LF / L,
            w * car.LF / L / 2 - dpitch + droll * car.LF / L,
        )
        u, v, r = self.vx, self.vy, self.yaw_rate
        for i in range(4):
            n_vx, n_vy, n_om, n_fz, n_ga, n_tb = _OUT[i]
            vxb = u - r * car.POS_Y[i] + self._xidot[i]
            vyb = v + r * car.POS_X[i]
            if i < 2:  # steered: body -> wheel frame, rotation by -delta
                vxw, vyw = c * vxb + s * vyb, -s * vxb + c * vyb
            else:
                vxw, vyw = vxb, vyb
            self._vxw[i] = vxw
            setattr(self, n_vx, vxw)
            setattr(self, n_vy, vyw)
            setattr(self, n_om, self._omega[i])
            setattr(self, n_fz, fz[i] if fz[i] > 0.0 else 0.0)
            setattr(self, n_ga, 0.0)
            setattr(self, n_tb, self._tb[i])

    # ------------------------------------------------------------------ controllers

    def _steer(self):
        """Path follower (the Stanley controller of Hoffmann, Tomlin, Montemerlo and
        Thrun, American Control Conference 2007, at the front axle) with a curvature feed-forward previewed `preview` s ahead:
        delta = L kappa_ref(x_f + u T) + (theta_ref - psi) + atan(k e / u)."""
        b = car.WIDTH
        cp, sp = math.cos(self.psi), math.sin(self.psi)
        xf, yf = self.x + car.LF * cp, self.y + car.LF * sp
        d = 0.5
        y0 = iso3888.reference_y(xf, b)
        th = math.atan((iso3888.reference_y(xf + d, b) - iso3888.reference_y(xf - d, b)) / (2 * d))
        e = (y0 - yf) * math.cos(th)
        xp = xf + self.preview * self.vx
        k_ff = (iso3888.reference_y(xp + d, b) - 2 * iso3888.reference_y(xp, b) + iso3888.reference_y(xp - d, b)) / (d * d)
        u = max(self.vx, 1.0)
        return car.WHEELBASE * k_ff + (th - self.psi) + math.atan(self.steer_gain * e / u)

    # ------------------------------------------------------------------ step

    def do_step(self, current_time, step_size):
        h = step_size
        self._steps += 1
        tnow = self.time  # the vehicle's own clock at the start of this step
        Fx = (self.Fx_fl, self.Fx_fr, self.Fx_rl, self.Fx_rr)
        Fy = (self.Fy_fl, self.Fy_fr, self.Fy_rl, self.Fy_rr)
        Mz = self.Mz_fl + self.Mz_fr + self.Mz_rl + self.Mz_rr
        My = (self.My_fl, self.My_fr, self.My_rl, self.My_rr)
        c, s = math.cos(self.delta), math.sin(self.delta)
        sfx = sfy = mz = 0.0
        ks, cs = car.RECESSION_STIFFNESS, car.RECESSION_DAMPING
        decay = math.exp(-h * ks / cs)
        for i in range(4):
            if i < 2:
                fxb, fyb = c * Fx[i] - s * Fy[i], s * Fx[i] + c * Fy[i]
            else:
                fxb, fyb = Fx[i], Fy[i]
            # massless hub: cs xi' + ks xi = Fx_b, solved exactly with Fx_b held
            xi = fxb / ks + (self._xi[i] - fxb / ks) * decay
            self._xi[i] = xi
            self._xidot[i] = (fxb - ks * xi) / cs
            sfx += fxb
            sfy += fyb
            mz += car.POS_X[i] * fyb - car.POS_Y[i] * fxb
        mz += Mz
        m = car.MASS
        u, v, r = self.vx, self.vy, self.yaw_rate
        self.ax = sfx / m  # accelerometer readings (tyre forces only)
        self.ay = sfy / m

        # brake and drive torques from the forces held over this step
        rw, iw = car.WHEEL_RADIUS, car.WHEEL_INERTIA
        td = [0.0] * 4
        tb = [0.0] * 4
        if self.scenario in ("abs", "slope") and tnow >= self.t_brake:
            ramp = min(1.0, (tnow - self.t_brake) / car.BRAKE_BUILD_UP)
            abs_on = u > self.abs_off_speed
            udot = sfx / m + car.G * math.sin(self._th)
            for i in range(4):
                avail = ramp * (car.BRAKE_MAX_FRONT if i < 2 else car.BRAKE_MAX_REAR)
                if abs_on:
                    target = (1.0 - self.abs_slip) * self._vxw[i] / self.rolling_radius
                    spin = (1.0 - self.abs_slip) * udot / self.rolling_radius
                    want = My[i] - rw * Fx[i] - iw * spin + iw * (self._omega[i] - target) / 0.02
                    tb[i] = min(max(want, 0.0), avail)
                else:
                    tb[i] = avail
        elif self.scenario == "lane-change":
            drive = 0.5 * m * rw * self.speed_gain * (self.v0 - u)
            td[2] = td[3] = drive

        # wheels: spin with a sticking brake
        for i in range(4):
            free = self._omega[i] + h * (My[i] - rw * Fx[i] + td[i]) / iw
            dbrake = h * tb[i] / iw
            if free >= 0.0:
                self._omega[i] = max(free - dbrake, 0.0)
            else:
                self._omega[i] = min(free + dbrake, 0.0)
        self._tb = tb

        # body: semi-implicit Euler
        u += h * (sfx / m + car.G * math.sin(self._th) + v * r)
        v += h * (sfy / m - u * r)
        r += h * mz / car.YAW_INERTIA
        psi = self.psi + h * r
        self.x += h * (u * math.cos(psi) - v * math.sin(psi))
        self.y += h * (u * math.sin(psi) + v * math.cos(psi))
        self.psi, self.vx, self.vy, self.yaw_rate = psi, u, v, r

        # quasi-static load transfer through the suspension lag
        a = 1.0 - math.exp(-h / car.SUSPENSION_LAG)
        self._sfx += a * (sfx - self._sfx)
        self._sfy += a * (sfy - self._sfy)

        self.time = self._steps * h
        if self.scenario == "lane-change":
            self.delta = self._steer()
        self._outputs()
        return True
