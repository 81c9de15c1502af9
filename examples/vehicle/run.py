"""run — one command per vehicle scenario of issue 17 (run from the project root):

    python examples/vehicle/run.py --engine osp|fmpy --scenario abs|lane-change|slope --out DIR
    python examples/vehicle/run.py --bench [--bench-seconds S]

Packages the tyre FMU it needs (`target/release/tyrekit package --out DIR/fmu/TyreKit.fmu`,
building tyrekit with cargo if the binary is missing), builds the vehicle FMU with
pythonfmu into DIR/fmu, runs the scenario in the chosen engine and writes
DIR/trace.csv, DIR/summary.json and PNG plots. `--bench` prints the real-time factor
of the whole system (vehicle + four tyres, 1 ms steps, ABS stop on dry road with the
relaxation model) in both engines.

Must never: write outside DIR (and the FMU build's temporary folder).
"""

import argparse
import json
import pathlib
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import numpy as np  # noqa: E402

import car  # noqa: E402
import cosim  # noqa: E402
import iso3888  # noqa: E402
import scenarios as S  # noqa: E402


def write_csv(path, cols, blocks):
    """blocks: list of (label dict, rows); label keys become leading columns."""
    keys = list(blocks[0][0].keys()) if blocks else []
    with open(path, "w") as f:
        f.write(",".join(keys + cols) + "\n")
        for label, rows in blocks:
            lead = ",".join(str(label[k]) for k in keys)
            for r in rows:
                f.write((lead + "," if lead else "") + ",".join(repr(float(v)) for v in r) + "\n")


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_abs(out, summary, traces):
    plt = _plt()
    fig, ax = plt.subplots(3, 1, figsize=(8, 9), dpi=80)
    for road, tr, cols, rows in traces:
        t = S.col(cols, rows, "t")
        ls = "-" if road == "dry" else "--"
        kw = dict(color=COLOURS[tr], label=f"{road} {tr}")
        ax[0].plot(t, S.col(cols, rows, "vehicle.vx") * 3.6, ls, **kw)
        f = S.stop_figures(cols, rows, 0.2)
        k = f["index"]
        # slip is undefined at standstill: shown up to the stop
        ax[1].plot(t[:k], S.col(cols, rows, "tyre_fl.kappa")[:k], ls, lw=0.8, **kw)
        ax[2].plot(t[k:] - t[k], 1e3 * (S.col(cols, rows, "vehicle.x")[k:] - S.col(cols, rows, "vehicle.x")[k]), ls,
                   **kw)
    ax[0].set_ylabel("speed (km/h)")
    ax[0].set_title("ABS stop from 100 km/h (1 ms co-simulation, 4 TyreKit FMUs + vehicle FMU)")
    ax[1].set_ylabel("front-left slip kappa (to the stop)")
    ax[1].set_xlabel("time (s)")
    ax[1].set_ylim(-0.4, 0.1)
    ax[2].set_ylabel("position after stop (mm)")
    ax[2].set_ylim(-60, 200)
    ax[2].set_xlabel("time after stop (s)")
    for a in ax:
        a.grid(True, alpha=0.3)
    ax[0].legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "abs.png")
    plt.close(fig)


def plot_lane_change(out, summary, cols, rows):
    plt = _plt()
    fig, ax = plt.subplots(4, 1, figsize=(8, 10), dpi=80)
    x, y = S.col(cols, rows, "vehicle.x"), S.col(cols, rows, "vehicle.y")
    for x0, x1, yr, yl in iso3888.lanes(car.WIDTH):
        for yy in (yr, yl):
            ax[0].plot([x0, x1], [yy, yy], "o", color="tab:orange", ms=4)
    ax[0].plot(x, y, label="CG path")
    ax[0].plot(x, [iso3888.reference_y(v, car.WIDTH) for v in x], ":", label="driver's reference")
    ax[0].set_xlim(-10, 135)
    ax[0].set_ylabel("y (m)")
    ax[0].set_title(f"ISO 3888-1 double lane change at 80 km/h (cone margin {summary['cone_margin_m']:.3f} m)")
    ax[0].legend(fontsize=7)
    t = S.col(cols, rows, "t")
    ax[1].plot(t, S.col(cols, rows, "vehicle.yaw_rate"))
    ax[1].set_ylabel("yaw rate (rad/s)")
    ax[2].plot(t, S.col(cols, rows, "vehicle.ay"))
    ax[2].set_ylabel("lateral acc. (m/s²)")
    ax[3].plot(t, np.degrees(S.col(cols, rows, "vehicle.delta")))
    ax[3].set_ylabel("road-wheel steer (deg)")
    ax[3].set_xlabel("time (s)")
    for a in ax:
        a.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "lane-change.png")
    plt.close(fig)


COLOURS = {"steady": "tab:blue", "relaxation": "tab:orange", "lugre": "tab:green"}


def plot_slope(out, summary, traces):
    plt = _plt()
    fig, ax = plt.subplots(2, 1, figsize=(8, 7), dpi=80)
    for (tr, cols, rows), r in zip(traces, summary["runs"]):
        t, x = S.col(cols, rows, "t"), S.col(cols, rows, "vehicle.x")
        f = S.stop_figures(cols, rows, 0.2)
        if f is None:
            continue
        k = f["index"]
        ax[0].plot(t[k:] - t[k], 1e3 * (x[k:] - x[k]), color=COLOURS[tr], label=tr)
        if tr != "steady":
            ax[1].plot(t[k:] - t[k], 1e3 * (x[k:] - x[k]), color=COLOURS[tr],
                       label=f"{tr}: creep {r['creep_mm']:.4f} mm from {summary['settle_s']:.0f} s to "
                             f"{summary['settle_s'] + r['creep_window_s']:.0f} s")
    ax[0].set_title("Parked facing down a 15 % grade after an ABS stop")
    ax[0].set_ylabel("travel after stop (mm)")
    ax[1].set_ylabel("travel after stop (mm)")
    ax[1].set_xlabel("time after stop (s)")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "slope.png")
    plt.close(fig)


def scenario(name, engine, out, park=S.SLOPE_PARK):
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tyre, veh = cosim.build_fmus(out / "fmu")
    if name == "abs":
        summary, traces = S.run_abs(tyre, veh, engine)
        write_csv(out / "trace.csv", traces[0][2],
                  [({"road": r, "transient": tr}, rows) for r, tr, _, rows in traces])
        plot_abs(out, summary, traces)
    elif name == "lane-change":
        summary, cols, rows = S.run_lane_change(tyre, veh, engine)
        write_csv(out / "trace.csv", cols, [({}, rows)])
        plot_lane_change(out, summary, cols, rows)
    elif name == "slope":
        summary, traces = S.run_slope(tyre, veh, engine, park=park)
        write_csv(out / "trace.csv", traces[0][1], [({"transient": tr}, rows) for tr, _, rows in traces])
        plot_slope(out, summary, traces)
    else:
        raise SystemExit(f"unknown scenario {name!r}: use abs, lane-change or slope")
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    return summary


def bench(seconds=5.0, workdir=None):
    """Real-time factor (simulated / wall time) of the whole system at 1 ms in both
    engines, and where the time goes in the fmpy master."""
    if workdir is None:
        with tempfile.TemporaryDirectory(prefix="vehicle-bench-") as tmp:
            return bench(seconds, tmp)
    tyre, veh = cosim.build_fmus(pathlib.Path(workdir))
    probe = cosim.tyre_probe(tyre, car.static_loads(), 1.0)
    system = cosim.System(tyre, veh, S.abs_vehicle(probe), {"transient": "relaxation"}, 1.0, S.STEP)
    res = {}
    for engine, fn in (("osp", cosim.bench_osp), ("fmpy", cosim.bench_fmpy)):
        runs = [fn(system, seconds) for _ in range(3)]
        wall = min(r[0] for r in runs)
        cpu = min(r[1] for r in runs)
        res[engine] = {"rtf_wall": seconds / wall, "rtf_cpu": seconds / cpu}
        print(f"{engine:5s}: {seconds:.1f} s simulated at 1 ms in {wall:.3f} s wall, {cpu:.3f} s CPU (best of 3): "
              f"real-time factor {seconds / wall:.1f} (wall), {seconds / cpu:.1f} (CPU of all threads)")
    for label, only in (("vehicle FMU alone", ["vehicle"]), ("4 tyre FMUs alone", [f"tyre_{w}" for w in car.WHEELS])):
        wall, cpu = min(cosim.bench_osp(system, seconds, only=only) for _ in range(3))
        print(f"osp, {label}: {1e6 * cpu / (seconds / S.STEP):.1f} us CPU per step (real-time factor "
              f"{seconds / wall:.1f} wall, {seconds / cpu:.1f} CPU)")
    prof = cosim.profile_fmpy(system, seconds)
    n = int(round(seconds / S.STEP))
    print("fmpy master, CPU per step: " + ", ".join(f"{k} {1e6 * v / n:.1f} us" for k, v in prof.items()))
    return res, prof


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--engine", choices=("osp", "fmpy"), default="fmpy")
    ap.add_argument("--scenario", choices=("abs", "lane-change", "slope"))
    ap.add_argument("--out", help="output directory")
    ap.add_argument("--park", type=float, default=S.SLOPE_PARK,
                    help="slope: length of the creep window after the car has settled (s, default 60)")
    ap.add_argument("--bench", action="store_true", help="print the real-time factor in both engines")
    ap.add_argument("--bench-seconds", type=float, default=5.0)
    a = ap.parse_args(argv)
    if a.bench:
        bench(a.bench_seconds, a.out)
        return 0
    if not a.scenario or not a.out:
        ap.error("--scenario and --out are required (or --bench)")
    t0 = time.perf_counter()
    summary = scenario(a.scenario, a.engine, a.out, a.park)
    print(json.dumps(summary, indent=2))
    print(f"{a.scenario} in {a.engine}: {time.perf_counter() - t0:.1f} s; wrote {a.out}/trace.csv, summary.json, "
          f"{a.scenario}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
