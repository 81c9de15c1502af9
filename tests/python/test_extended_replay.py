"""An extended tyre file simulates its finding by itself: the FMU with every
parameter at its default (transient = "file", input_mode = "velocities") and
`tyrekit replay` without flags run the same model on the same recording.

The file is the packaged tyre plus what `tyrekit diagnose` writes for a
relaxation finding ([TYREKIT] TRANSIENT = 'relaxation', longer relaxation
lengths) and a thermal one ([THERMAL]): both are stateful, so a mismatch in
the transient model, its settling or the time base shows as a lag error.
The recording has a wheel speed, so replay takes kappa from omega and the
tyre's own Re(Fz) as the FMU does.
"""

import csv
import math
import os
import subprocess

import numpy as np

from conftest import TARGET

TYREKIT = TARGET / "release" / "tyrekit"

EXTENSION = """
[TYREKIT]
TRANSIENT                = 'relaxation'
[THERMAL]
CAPACITY                 = 2000
COOLING                  = 40
SHARE                    = 0.5
MU_T0                    = 0.0
MU_T1                    = -0.2
MU_T2                    = 0.0
"""


def recording(path, r0):
    """20 s at 100 Hz: slip-angle sine ±6° at 0.25 Hz, slip-ratio sine ±0.05
    at 0.1 Hz, load 3000–5000 N, 15 m/s; omega from the slip ratio and R0
    (any wheel speed will do: both sides take kappa from it the same way)."""
    t = np.arange(0.0, 20.0, 0.01)
    vx = np.full_like(t, 15.0)
    alpha = np.radians(6.0) * np.sin(2 * math.pi * 0.25 * t)
    kappa = 0.05 * np.sin(2 * math.pi * 0.1 * t)
    fz = 4000.0 + 1000.0 * np.sin(2 * math.pi * 0.05 * t)
    omega = (1.0 + kappa) * vx / r0
    zero = np.zeros_like(t)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time", "Vx", "omega", "Fz", "kappa", "alpha", "gamma", "P", "Fx", "Fy", "Mz"])
        for row in zip(t, vx, omega, fz, kappa, alpha, zero, zero, zero, zero, zero):
            w.writerow([repr(float(x)) for x in row])
    return dict(t=t, vx=vx, omega=omega, fz=fz, alpha=alpha)


def test_extended_file_in_fmu_reproduces_replay(make, vr, unzipdir, tmpdir_path):
    base = os.path.join(unzipdir, "resources", "tyre.tir")
    tir = tmpdir_path / "extended.tir"
    tir.write_text(open(base).read() + EXTENSION)
    rec = tmpdir_path / "rec.csv"
    x = recording(rec, r0=0.3)
    out = tmpdir_path / "sim.csv"
    subprocess.run(
        [str(TYREKIT), "replay", str(rec), "--tir", str(tir), "--out", str(out)],
        check=True,
    )
    with open(out) as f:
        rows = list(csv.DictReader(f))
    sim_t = np.array([float(r["time"]) for r in rows])
    assert len(sim_t) > 1000, "replay dropped most of the recording"
    i0 = int(np.argmin(abs(x["t"] - sim_t[0])))
    assert abs(x["t"][i0] - sim_t[0]) < 1e-9

    fmu = make("extended", strings={"tyre_file": str(tir)})  # all else default
    def inputs(i):
        fmu.setReal(
            [vr["vx"], vr["vy"], vr["omega"], vr["Fz"]],
            [x["vx"][i], math.tan(x["alpha"][i]) * abs(x["vx"][i]), x["omega"][i], x["fz"][i]],
        )
    # replay settles its state on the first sample with one 5 s step of its
    # inputs held (ReplayOptions::settle_time): the FMU gets the same step,
    # then the recording's steps (FMU time = 5 s + recording time − t0).
    inputs(i0)
    fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=5.0)
    tau = 5.0
    out_vr = [vr["Fx"], vr["Fy"], vr["Mz"]]
    got = [fmu.getReal(out_vr)]
    for k in range(1, len(sim_t)):
        i = i0 + k
        assert abs(x["t"][i] - sim_t[k]) < 1e-9
        inputs(i)
        h = sim_t[k] - sim_t[k - 1]
        fmu.doStep(currentCommunicationPoint=tau, communicationStepSize=h)
        tau += h
        got.append(fmu.getReal(out_vr))
    got = np.array(got)
    want = np.array([[float(r["Fx_sim"]), float(r["Fy_sim"]), float(r["Mz_sim"])] for r in rows])
    # The same code on the same inputs: equal to rounding (the CSV prints
    # shortest round-trip floats; 1e-6 of the channel's range leaves room
    # only for summation order, not for another model or time base).
    for c, name in enumerate(["Fx", "Fy", "Mz"]):
        scale = np.ptp(want[:, c])
        assert scale > 0, name
        err = np.max(abs(got[:, c] - want[:, c]))
        print(f"{name}: max |FMU - replay| = {err:.3g} (range {scale:.4g})")
        assert err <= 1e-6 * scale, f"{name}: max |FMU - replay| = {err} (range {scale})"
    # And the file's transient model is really on: a steady replay differs.
    steady = tmpdir_path / "steady.csv"
    subprocess.run(
        [str(TYREKIT), "replay", str(rec), "--tir", str(tir), "--out", str(steady), "--transient", "steady"],
        check=True,
    )
    with open(steady) as f:
        fy_steady = np.array([float(r["Fy_sim"]) for r in csv.DictReader(f)])
    assert np.max(abs(fy_steady - want[:, 1])) > 0.01 * np.ptp(want[:, 1])
