"""scenarios — the three manoeuvres of issue 17 on the vehicle system, run in either
engine, and the figures each one reports:

- `abs`: straight-line ABS braking from 100 km/h to standstill on a dry (mu_scale 1)
  and a wet (0.6) road, per transient model (steady, relaxation, lugre), beside the
  textbook stopping distance v0^2 / (2 mu_peak g) (e.g. Gillespie, *Fundamentals of
  Vehicle Dynamics*, eq. 3-9 with constant deceleration mu g), mu_peak being the
  tyre's own peak longitudinal friction at the static wheel loads, found by sweeping
  the slip through the FMU (cosim.tyre_probe);
- `lane-change`: ISO 3888-1 double lane change at 80 km/h (relaxation model, dry);
- `slope`: braking to a stop facing down a 15 % grade, then parked 60 s.

Distances and times are measured from the brake onset; the car has stopped at the
first recorded sample with speed <= STOP_SPEED.

Must never: tune a vehicle or controller constant per transient model (all runs of a
scenario share every setting except the one compared).
"""

import math

import numpy as np

import car
import cosim

STEP = 1e-3  # s, communication step of every run
STOP_SPEED = 1e-3  # m/s: "stopped"
ROADS = (("dry", 1.0), ("wet", 0.6))
TRANSIENTS = ("steady", "relaxation", "lugre")
SLOPE_GRADE = 0.15
SLOPE_PARK = 60.0  # s over which the parked car's creep is counted
SETTLE = 2.0  # s after the stop before that window opens (the elastic spring-back rings out)


def run(system, engine, t_end, record_every):
    """(columns, rows) of one run: columns = ["t", "instance.variable", ...]."""
    if engine == "osp":
        rows, wall = cosim.run_osp(system, t_end, record_every)
    elif engine == "fmpy":
        rows, wall = cosim.run_fmpy(system, t_end, record_every)
    else:
        raise ValueError(f"engine must be osp or fmpy, got {engine!r}")
    cols = ["t"] + [f"{i}.{v}" for i, v in system.trace_columns()]
    return cols, rows


def col(cols, rows, name):
    return rows[:, cols.index(name)]


# ---------------------------------------------------------------- abs


def abs_vehicle(probe, v0=100.0 / 3.6):
    return {
        "scenario": "abs",
        "v0": v0,
        "t_brake": 0.2,
        # An ideal ABS: it holds the slip of the tyre's peak on this road.
        "abs_slip": probe["kappa_peak"],
        "rolling_radius": probe["re"],
    }


def stop_figures(cols, rows, t_brake):
    t, x, v = col(cols, rows, "t"), col(cols, rows, "vehicle.x"), col(cols, rows, "vehicle.vx")
    x_brake = float(np.interp(t_brake, t, x))
    k = np.flatnonzero((t > t_brake) & (v <= STOP_SPEED))
    if len(k) == 0:
        return None
    k = int(k[0])
    return dict(stopping_distance_m=float(x[k] - x_brake), stopping_time_s=float(t[k] - t_brake), index=k)


def run_abs(tyre_fmu, vehicle_fmu, engine, t_after_stop=3.0, roads=ROADS, transients=TRANSIENTS):
    """Every (road, transient) run; returns (summary, traces) with traces a list of
    (road, transient, cols, rows)."""
    runs, traces = [], []
    for road, mu in roads:
        probe = cosim.tyre_probe(tyre_fmu, car.static_loads(), mu)
        veh = abs_vehicle(probe)
        v0 = veh["v0"]
        textbook = v0 * v0 / (2.0 * probe["mu_peak"] * car.G)
        # duration: the textbook stop with 30 % margin, plus the standstill
        t_end = veh["t_brake"] + 1.3 * v0 / (probe["mu_peak"] * car.G) + t_after_stop
        for tr in transients:
            system = cosim.System(tyre_fmu, vehicle_fmu, veh, {"transient": tr}, mu, STEP)
            cols, rows = run(system, engine, t_end, 5)
            f = stop_figures(cols, rows, veh["t_brake"])
            if f is None:
                raise RuntimeError(f"abs {road} {tr}: the car did not stop within {t_end:.1f} s")
            runs.append({
                "road": road,
                "transient": tr,
                "stopping_distance_m": f["stopping_distance_m"],
                "stopping_time_s": f["stopping_time_s"],
                "textbook_distance_m": textbook,
                "mu_peak": probe["mu_peak"],
            })
            traces.append((road, tr, cols, rows))
    head = next((r for r in runs if r["road"] == "dry" and r["transient"] == "relaxation"), runs[0])
    summary = {k: head[k] for k in ("stopping_distance_m", "stopping_time_s", "textbook_distance_m", "mu_peak")}
    summary["runs"] = runs
    return summary, traces


def standstill(cols, rows, t_brake, after=2.0):
    """Largest |speed| from `after` s past the stop to the end of the run (m/s) and
    the largest backward travel after the stop (m, > 0 = the car reversed)."""
    f = stop_figures(cols, rows, t_brake)
    t, x, v = col(cols, rows, "t"), col(cols, rows, "vehicle.x"), col(cols, rows, "vehicle.vx")
    k = f["index"]
    late = t >= t[k] + after
    return float(np.max(np.abs(v[late]))), float(x[k] - np.min(x[k:])), float(t[-1] - t[k])


# ---------------------------------------------------------------- lane change


def lane_change_vehicle():
    return {"scenario": "lane-change", "v0": 80.0 / 3.6, "x0": -40.0, "rolling_radius": 0.305}


def run_lane_change(tyre_fmu, vehicle_fmu, engine, transient="relaxation", t_end=8.5):
    import iso3888

    veh = lane_change_vehicle()
    probe = cosim.tyre_probe(tyre_fmu, car.static_loads(), 1.0)
    veh["rolling_radius"] = probe["re"]
    system = cosim.System(tyre_fmu, vehicle_fmu, veh, {"transient": transient}, 1.0, STEP)
    cols, rows = run(system, engine, t_end, 10)
    x, y, psi = col(cols, rows, "vehicle.x"), col(cols, rows, "vehicle.y"), col(cols, rows, "vehicle.psi")
    margin, where = iso3888.violations(x, y, psi, car.WIDTH, car.LF, car.LR)
    gate = (x >= -car.LF) & (x <= sum(iso3888.SECTIONS) + car.LR)
    v = col(cols, rows, "vehicle.vx")
    summary = {
        "speed_kmh": veh["v0"] * 3.6,
        "transient": transient,
        "inside_cones": bool(margin < 0.0),
        "cone_margin_m": float(-margin),
        "closest_cone_x_m": None if where is None else float(where),
        "peak_lateral_acceleration_mps2": float(np.max(np.abs(col(cols, rows, "vehicle.ay")[gate]))),
        "peak_yaw_rate_radps": float(np.max(np.abs(col(cols, rows, "vehicle.yaw_rate")[gate]))),
        "peak_steer_rad": float(np.max(np.abs(col(cols, rows, "vehicle.delta")[gate]))),
        "exit_speed_kmh": float(np.interp(sum(iso3888.SECTIONS), x, v) * 3.6),
        "vehicle_width_m": car.WIDTH,
    }
    return summary, cols, rows


# ---------------------------------------------------------------- slope


def slope_vehicle(probe):
    return {
        "scenario": "slope",
        "grade": SLOPE_GRADE,
        "v0": 5.0,
        "t_brake": 0.2,
        "abs_slip": probe["kappa_peak"],
        "rolling_radius": probe["re"],
    }


def run_slope(tyre_fmu, vehicle_fmu, engine, park=SLOPE_PARK, transients=TRANSIENTS):
    probe = cosim.tyre_probe(tyre_fmu, car.static_loads(), 1.0)
    veh = slope_vehicle(probe)
    t_end = veh["t_brake"] + 1.5 * veh["v0"] / (probe["mu_peak"] * car.G - car.G * math.sin(math.atan(SLOPE_GRADE))) + SETTLE + park
    runs, traces = [], []
    for tr in transients:
        system = cosim.System(tyre_fmu, vehicle_fmu, veh, {"transient": tr}, 1.0, STEP)
        cols, rows = run(system, engine, t_end, 10)
        f = stop_figures(cols, rows, veh["t_brake"])
        t, x, v = col(cols, rows, "t"), col(cols, rows, "vehicle.x"), col(cols, rows, "vehicle.vx")
        if f is None:
            runs.append({"transient": tr, "stopped": False, "speed_at_end_mps": float(v[-1])})
            traces.append((tr, cols, rows))
            continue
        k = f["index"]
        t_stop = t[k]
        settled = float(np.interp(t_stop + SETTLE, t, x))
        end = float(np.interp(min(t_stop + SETTLE + park, t[-1]), t, x))
        after = t >= t_stop + SETTLE
        # chatter: sign changes of the speed in the creep window, beyond 0.1 mm/s
        vs = v[after]
        vs = vs[np.abs(vs) > 1e-4]
        runs.append({
            "transient": tr,
            "stopped": True,
            "stopping_time_s": f["stopping_time_s"],
            "creep_window_s": float(min(SETTLE + park, t[-1] - t_stop) - SETTLE),
            "creep_mm": 1e3 * (end - settled),
            "spring_back_mm": 1e3 * float(x[k] - np.min(x[k:])),
            "max_speed_parked_mps": float(np.max(np.abs(v[after]))) if after.any() else 0.0,
            "speed_sign_changes_parked": int(np.count_nonzero(np.diff(np.sign(vs)) != 0)),
        })
        traces.append((tr, cols, rows))
    return {"grade": SLOPE_GRADE, "settle_s": SETTLE, "runs": runs}, traces
