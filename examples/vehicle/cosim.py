"""cosim — the vehicle system (one Vehicle.fmu + four instances of one TyreKit.fmu) and
the two co-simulation engines that run it: OSP libcosim (through libcosimpy and an
OspSystemStructure.xml written here) and a master loop over fmpy written for this
project. Both use the same fixed step and the same Jacobi exchange as libcosim's
`fixed_step_algorithm`: at each step every instance gets the outputs the others
produced at the end of the previous step, all step from t to t + h, then the outputs
are read; initialisation iterates get/transfer once per instance in initialisation
mode before exitInitializationMode, as libcosim does.

Must never: set a value in one engine that the other does not (both take every
start value, parameter and connection from the one `System` description).
"""

import ctypes
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from xml.sax.saxutils import quoteattr

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))
import car  # noqa: E402

# Tyre <- vehicle, vehicle <- tyre (names of the TyreKit FMU on the left).
TYRE_FROM_VEHICLE = ("vx", "vy", "omega", "Fz", "gamma")
VEHICLE_FROM_TYRE = ("Fx", "Fy", "Mz", "My")
# Tyre outputs kept in the trace besides the connected ones.
TYRE_TRACE = ("Fx", "Fy", "Mz", "My", "kappa", "alpha", "Re")
VEHICLE_TRACE = ("time", "x", "y", "psi", "vx", "vy", "yaw_rate", "ax", "ay", "delta") + tuple(
    f"{q}_{w}" for w in car.WHEELS for q in ("omega", "Fz", "Tb")
)


# ---------------------------------------------------------------- building the FMUs


def tyrekit_binary():
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    exe = target / "release" / "tyrekit"
    if not exe.exists():
        print(f"{exe} missing: building it with cargo build --release", file=sys.stderr)
        subprocess.run(["cargo", "build", "--release", "--bin", "tyrekit"], cwd=ROOT, check=True)
    return exe


def build_fmus(workdir):
    """Package TyreKit.fmu (`tyrekit package --out`) and build Vehicle.fmu with pythonfmu
    into workdir; returns (tyre_fmu, vehicle_fmu)."""
    workdir = pathlib.Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    tyre = workdir / "TyreKit.fmu"
    subprocess.run([str(tyrekit_binary()), "package", "--out", str(tyre)], cwd=ROOT, check=True,
                   stdout=subprocess.DEVNULL)
    veh = workdir / "Vehicle.fmu"
    # pythonfmu's builder writes the FMU from the script and its project files.
    from pythonfmu.builder import FmuBuilder

    with tempfile.TemporaryDirectory(prefix="vehicle-build-") as tmp:
        for f in ("vehicle.py", "car.py", "iso3888.py"):
            shutil.copy(HERE / f, tmp)
        FmuBuilder.build_FMU(pathlib.Path(tmp) / "vehicle.py", dest=workdir,
                             project_files=[pathlib.Path(tmp) / "car.py", pathlib.Path(tmp) / "iso3888.py"])
    return tyre, veh


def tyre_inflation_pressure(tyre_fmu):
    """INFLPRES (Pa) of the tyre file packaged in the FMU (to set `p` explicitly)."""
    with zipfile.ZipFile(tyre_fmu) as z:
        text = z.read("resources/tyre.tir").decode("latin-1")
    m = re.search(r"^\s*INFLPRES\s*=\s*([-+0-9.eE]+)", text, re.M)
    if not m:
        raise RuntimeError(f"{tyre_fmu}: resources/tyre.tir has no INFLPRES")
    return float(m.group(1))


# ---------------------------------------------------------------- the system


class System:
    """Instances, start values and connections of the vehicle system.

    vehicle: dict of the vehicle FMU's parameters (name -> value);
    tyre: dict of the tyre parameters shared by the four instances (transient, ...);
    mu_scale: road friction scale for all four tyres.
    Every tyre input is given an explicit start value (the FMU's own start values
    are those of its built-in tyre at 10 m/s): the connected ones get the vehicle's
    initial outputs through the initialisation exchange, the others are set here.
    """

    def __init__(self, tyre_fmu, vehicle_fmu, vehicle, tyre, mu_scale, step=1e-3):
        self.tyre_fmu, self.vehicle_fmu = str(tyre_fmu), str(vehicle_fmu)
        self.vehicle = dict(vehicle)
        self.tyre = dict(tyre)
        self.mu_scale = float(mu_scale)
        self.step = step
        self.p = tyre_inflation_pressure(tyre_fmu)
        v0 = float(self.vehicle.get("v0", 0.0))
        rr = float(self.vehicle.get("rolling_radius", 0.305))
        fz0 = car.static_loads(0.0)
        self.instances = {"vehicle": (self.vehicle_fmu, self._vehicle_start())}
        for i, w in enumerate(car.WHEELS):
            start = {
                "side": car.SIDE[i],
                **self.tyre,
                # explicit start values for every input
                "vx": v0, "vy": 0.0, "omega": v0 / rr, "Fz": fz0[i], "gamma": 0.0,
                "p": self.p, "phit": 0.0, "mu_scale": self.mu_scale, "kappa_in": 0.0, "alpha_in": 0.0,
            }
            self.instances[f"tyre_{w}"] = (self.tyre_fmu, start)
        self.connections = []  # (from_instance, from_var, to_instance, to_var)
        for w in car.WHEELS:
            for q in TYRE_FROM_VEHICLE:
                self.connections.append(("vehicle", f"{q}_{w}", f"tyre_{w}", q))
            for q in VEHICLE_FROM_TYRE:
                self.connections.append((f"tyre_{w}", q, "vehicle", f"{q}_{w}"))

    def _vehicle_start(self):
        return dict(self.vehicle)

    def trace_columns(self):
        cols = [("vehicle", q) for q in VEHICLE_TRACE]
        for w in car.WHEELS:
            cols += [(f"tyre_{w}", q) for q in TYRE_TRACE]
        return cols

    def write_osp(self, path, only=None):
        """OspSystemStructure.xml (OSP-IS) beside the FMUs it names. only: a subset of
        instance names (connections among them kept), for the benchmark's breakdown."""
        path = pathlib.Path(path)
        lines = [
            '<?xml version="1.0" encoding="utf-8"?>',
            '<OspSystemStructure xmlns="http://opensimulationplatform.com/MSMI/OSPSystemStructure" version="0.1">',
            "  <StartTime>0.0</StartTime>",
            f"  <BaseStepSize>{self.step!r}</BaseStepSize>",
            "  <Algorithm>fixedStep</Algorithm>",
            "  <Simulators>",
        ]
        for name, (fmu, start) in self.instances.items():
            if only is not None and name not in only:
                continue
            rel = os.path.relpath(fmu, path.parent)
            lines.append(f"    <Simulator name={quoteattr(name)} source={quoteattr(rel)} stepSize={quoteattr(repr(self.step))}>")
            lines.append("      <InitialValues>")
            for k, v in start.items():
                lines.append(f"        <InitialValue variable={quoteattr(k)}>{_osp_value(v)}</InitialValue>")
            lines.append("      </InitialValues>")
            lines.append("    </Simulator>")
        lines.append("  </Simulators>")
        lines.append("  <Connections>")
        for a, av, b, bv in self.connections:
            if only is not None and not (a in only and b in only):
                continue
            lines.append("    <VariableConnection>")
            lines.append(f"      <Variable simulator={quoteattr(a)} name={quoteattr(av)}/>")
            lines.append(f"      <Variable simulator={quoteattr(b)} name={quoteattr(bv)}/>")
            lines.append("    </VariableConnection>")
        lines.append("  </Connections>")
        lines.append("</OspSystemStructure>")
        path.write_text("\n".join(lines) + "\n")
        return path


def _osp_value(v):
    if isinstance(v, bool):
        return f'<Boolean value="{str(v).lower()}"/>'
    if isinstance(v, int):
        return f'<Integer value="{v}"/>'
    if isinstance(v, float):
        return f'<Real value="{v!r}"/>'
    return f"<String value={quoteattr(str(v))}/>"


# ---------------------------------------------------------------- OSP libcosim


def _quiet_libcosim():
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.WARNING)


def run_osp(system, t_end, record_every=10, workdir=None):
    """Run the system in libcosim; returns (trace array [n, 1 + columns], wall seconds):
    one row every `record_every` steps (and at the end). The OspSystemStructure.xml is
    written to workdir, default the tyre FMU's folder."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver

    _quiet_libcosim()
    osp = system.write_osp(pathlib.Path(workdir or pathlib.Path(system.tyre_fmu).parent) / "OspSystemStructure.xml")
    ex = CosimExecution.from_osp_config_file(str(osp))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    cols = system.trace_columns()
    index = {}
    for name in system.instances:
        idx = ex.slave_index_from_instance_name(name)
        vrs = {v.name.decode(): v.reference for v in ex.slave_variables(idx)}
        index[name] = (idx, vrs)
    groups = {}
    for j, (inst, var) in enumerate(cols):
        idx, vrs = index[inst]
        groups.setdefault(idx, ([], []))
        groups[idx][0].append(vrs[var])
        groups[idx][1].append(j)
    n_steps = int(round(t_end / system.step))
    rows = []

    def record(t):
        row = np.empty(len(cols) + 1)
        row[0] = t
        for idx, (vrs, js) in groups.items():
            vals = obs.last_real_values(idx, vrs)
            row[1 + np.array(js)] = vals
        rows.append(row)

    t0 = time.perf_counter()
    done = 0
    # The first `step` call initialises (libcosim has no separate call for it), so
    # both engines record from the end of the first chunk on.
    while done < n_steps:
        k = min(record_every, n_steps - done)
        if not ex.step(k):
            from libcosimpy._internal import get_last_error_message

            raise RuntimeError(f"libcosim step failed at step {done}: {get_last_error_message()}")
        done += k
        record(done * system.step)
    wall = time.perf_counter() - t0
    return np.array(rows), wall


def bench_osp(system, t_end, workdir=None, only=None):
    """(wall seconds, process CPU seconds, all threads) of libcosim's simulate_until
    over t_end without observation; only: run just these instances (unconnected
    inputs stay at their start values)."""
    from libcosimpy.CosimExecution import CosimExecution

    _quiet_libcosim()
    name = "OspSystemStructure.xml" if only is None else "bench-subset/OspSystemStructure.xml"
    path = pathlib.Path(workdir or pathlib.Path(system.tyre_fmu).parent) / name
    path.parent.mkdir(parents=True, exist_ok=True)
    osp = system.write_osp(path, only)
    ex = CosimExecution.from_osp_config_file(str(osp))
    t0, c0 = time.perf_counter(), time.process_time()
    if not ex.simulate_until(int(round(t_end * 1e9))):
        raise RuntimeError("libcosim simulate_until failed")
    return time.perf_counter() - t0, time.process_time() - c0


# ---------------------------------------------------------------- fmpy master


class _Slave:
    """One FMU instance driven through its raw FMI 2.0 functions (fmpy loads the
    library and binds the C signatures; the master calls them with preallocated
    ctypes arrays, so a step costs three C calls per instance)."""

    def __init__(self, name, fmu_path, unzip_cache, start):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        if fmu_path not in unzip_cache:
            unzip_cache[fmu_path] = (extract(fmu_path), read_model_description(fmu_path))
        d, md = unzip_cache[fmu_path]
        self.name = name
        self.vars = {v.name: v for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                             instanceName=name)
        self.fmu.instantiate()
        self.start = start
        self.c = self.fmu.component
        dll = self.fmu.dll
        self._set = dll.fmi2SetReal
        self._get = dll.fmi2GetReal
        self._step = dll.fmi2DoStep

    def vr(self, name):
        return self.vars[name].valueReference

    def apply_start(self, which):
        """Set start values: which = 'params' (String/Integer/Boolean and parameters)
        or 'inputs' (Real inputs)."""
        for k, v in self.start.items():
            var = self.vars[k]
            is_input = var.causality == "input"
            if (which == "inputs") != is_input:
                continue
            r = [var.valueReference]
            if isinstance(v, bool):
                self.fmu.setBoolean(r, [v])
            elif isinstance(v, int):
                self.fmu.setInteger(r, [v])
            elif isinstance(v, float):
                self.fmu.setReal(r, [v])
            else:
                self.fmu.setString(r, [str(v)])

    def bind(self, in_names, in_buf, out_names, out_buf):
        """in_buf/out_buf: ctypes double arrays (views into the master's buffers)."""
        vr_t = ctypes.c_uint32
        self.in_vr = (vr_t * len(in_names))(*[self.vr(n) for n in in_names])
        self.n_in = len(in_names)
        self.in_buf = in_buf
        self.out_vr = (vr_t * len(out_names))(*[self.vr(n) for n in out_names])
        self.n_out = len(out_names)
        self.out_buf = out_buf

    def push(self):
        if self._set(self.c, self.in_vr, self.n_in, self.in_buf) != 0:
            raise RuntimeError(f"{self.name}: fmi2SetReal failed")

    def pull(self):
        if self._get(self.c, self.out_vr, self.n_out, self.out_buf) != 0:
            raise RuntimeError(f"{self.name}: fmi2GetReal failed")

    def do_step(self, t, h):
        if self._step(self.c, t, h, 1) != 0:
            raise RuntimeError(f"{self.name}: fmi2DoStep failed at t = {t}")


class FmpyMaster:
    """The project's own master over fmpy: libcosim's fixed-step Jacobi algorithm."""

    def __init__(self, system):
        self.system = system
        cache = self._unzipped = {}
        self.slaves = {n: _Slave(n, fmu, cache, start) for n, (fmu, start) in system.instances.items()}
        veh = self.slaves["vehicle"]
        # One buffer holding every connected value: the vehicle's outputs (20) and
        # inputs (16); each tyre reads/writes a contiguous view of it (no copies).
        nv, nt = len(TYRE_FROM_VEHICLE), len(VEHICLE_FROM_TYRE)
        self.vout = (ctypes.c_double * (4 * nv))()
        self.vin = (ctypes.c_double * (4 * nt))()
        vout_names, vin_names = [], []
        for i, w in enumerate(car.WHEELS):
            vout_names += [f"{q}_{w}" for q in TYRE_FROM_VEHICLE]
            vin_names += [f"{q}_{w}" for q in VEHICLE_FROM_TYRE]
            tyre = self.slaves[f"tyre_{w}"]
            tin = (ctypes.c_double * nv).from_buffer(self.vout, 8 * nv * i)
            tout = (ctypes.c_double * nt).from_buffer(self.vin, 8 * nt * i)
            tyre.bind(TYRE_FROM_VEHICLE, tin, VEHICLE_FROM_TYRE, tout)
        veh.bind(vin_names, self.vin, vout_names, self.vout)
        self.order = list(self.slaves.values())
        # trace columns
        self.cols = system.trace_columns()
        self.trace_get = []
        for name, s in self.slaves.items():
            js = [j for j, (inst, _) in enumerate(self.cols) if inst == name]
            vrs = (ctypes.c_uint32 * len(js))(*[s.vr(self.cols[j][1]) for j in js])
            self.trace_get.append((s, vrs, len(js), (ctypes.c_double * len(js))(), np.array(js) + 1))

    def initialize(self):
        for s in self.order:
            s.apply_start("params")
        for s in self.order:
            s.fmu.setupExperiment(startTime=0.0)
            s.fmu.enterInitializationMode()
        for s in self.order:
            s.apply_start("inputs")
        # libcosim: as many get/transfer iterations as there are simulators
        for _ in range(len(self.order)):
            for s in self.order:
                s.pull()
            for s in self.order:
                s.push()
        for s in self.order:
            s.fmu.exitInitializationMode()
        for s in self.order:
            s.pull()

    def record(self, t):
        row = np.empty(len(self.cols) + 1)
        row[0] = t
        for s, vrs, n, buf, js in self.trace_get:
            if s._get(s.c, vrs, n, buf) != 0:
                raise RuntimeError(f"{s.name}: fmi2GetReal failed")
            row[js] = buf[:]
        return row

    def run(self, t_end, record_every=10, record=True):
        h = self.system.step
        h_ns = int(round(h * 1e9))
        n_steps = int(round(t_end / h))
        order = self.order
        rows = []
        t0 = time.perf_counter()
        self.initialize()
        for k in range(n_steps):
            t = k * h_ns / 1e9  # libcosim's time points are integer nanoseconds
            for s in order:
                s.push()
            for s in order:
                s.do_step(t, h)
            for s in order:
                s.pull()
            if record and ((k + 1) % record_every == 0 or k + 1 == n_steps):
                rows.append(self.record((k + 1) * h_ns / 1e9))
        wall = time.perf_counter() - t0
        return np.array(rows), wall

    def free(self):
        for s in self.order:
            try:
                s.fmu.terminate()
                s.fmu.freeInstance()
            except Exception:
                pass
        for d, _ in self._unzipped.values():
            shutil.rmtree(d, ignore_errors=True)


def run_fmpy(system, t_end, record_every=10):
    m = FmpyMaster(system)
    try:
        return m.run(t_end, record_every)
    finally:
        m.free()


def bench_fmpy(system, t_end):
    """(wall seconds, process CPU seconds) of an unrecorded run."""
    m = FmpyMaster(system)
    try:
        c0 = time.process_time()
        wall = m.run(t_end, record=False)[1]
        return wall, time.process_time() - c0
    finally:
        m.free()


# ---------------------------------------------------------------- tyre properties


def tyre_probe(tyre_fmu, loads, mu_scale=1.0, side="left"):
    """The tyre's own figures through the FMU (steady model, prescribed slips):
    returns dict(mu_peak, kappa_peak, re) where mu_peak = sum_i max_k |Fx(k, Fz_i)| /
    sum_i Fz_i over the given wheel loads (the car's peak braking force at those
    loads over its weight), kappa_peak the braking slip of the largest |Fx| at the
    mean load, and re the free-rolling radius at the mean load (at 20 m/s)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(tyre_fmu))
    d = extract(str(tyre_fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="probe")
    fmu.instantiate()
    try:
        fmu.setString([vr["input_mode"], vr["transient"], vr["side"]], ["slips", "steady", side])
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        p = tyre_inflation_pressure(tyre_fmu)
        base = dict(vx=20.0, vy=0.0, omega=20.0 / 0.3, Fz=4000.0, gamma=0.0, p=p, phit=0.0,
                    mu_scale=float(mu_scale), kappa_in=0.0, alpha_in=0.0)
        fmu.setReal([vr[k] for k in base], list(base.values()))
        fmu.exitInitializationMode()
        clock = [0, 1e-3]  # steps taken, step size (the FMU checks the time)

        def step():
            fmu.doStep(clock[0] * clock[1], clock[1])
            clock[0] += 1

        kappas = -np.linspace(0.0, 0.6, 601)

        def sweep(fz):
            fx = []
            for k in kappas:
                fmu.setReal([vr["Fz"], vr["kappa_in"]], [fz, k])
                step()
                fx.append(fmu.getReal([vr["Fx"]])[0])
            return np.abs(np.array(fx))

        peak = sum(float(sweep(fz).max()) for fz in loads)
        mean = float(np.mean(loads))
        fx = sweep(mean)
        fmu.setReal([vr["Fz"], vr["kappa_in"]], [mean, 0.0])
        step()
        re = fmu.getReal([vr["Re"]])[0]
        return dict(mu_peak=peak / float(np.sum(loads)), kappa_peak=float(-kappas[np.argmax(fx)]), re=float(re))
    finally:
        fmu.terminate()
        fmu.freeInstance()
        shutil.rmtree(d, ignore_errors=True)


def profile_fmpy(system, t_end):
    """CPU seconds of this thread (the fmpy master steps every FMU in its own thread)
    spent in each part of the loop over t_end: the vehicle FMU's three calls
    (pythonfmu: Python code), the four tyre FMUs' calls, and the loop itself (the
    timers' own cost, ~1 us per reading, falls into the parts they bracket)."""
    m = FmpyMaster(system)
    try:
        h = system.step
        h_ns = int(round(h * 1e9))
        n = int(round(t_end / h))
        veh = m.slaves["vehicle"]
        tyres = [s for s in m.order if s is not veh]
        m.initialize()
        pc = time.thread_time
        tv = tt = 0.0
        t0 = pc()
        for k in range(n):
            t = k * h_ns / 1e9
            # the Jacobi step's three phases, each vehicle first, then the tyres
            for phase, args in (("push", ()), ("do_step", (t, h)), ("pull", ())):
                a = pc()
                getattr(veh, phase)(*args)
                b = pc()
                for s in tyres:
                    getattr(s, phase)(*args)
                tv += b - a
                tt += pc() - b
        total = pc() - t0
        return {"vehicle FMU (pythonfmu)": tv, "4 tyre FMUs": tt, "master loop": total - tv - tt}
    finally:
        m.free()
