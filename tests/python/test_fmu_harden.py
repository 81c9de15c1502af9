"""Issue 16 through FMPy: absurd inputs refused, no state poisoning, LuGre
within its friction limit, turn slip at standstill, tyre_file limited to
regular files, FMU states that name no file, logging categories honoured.

Limits come from the modelDescription (min/max), never from the FMU's answers.
"""

import math
import os
import threading
import time

import pytest
from fmpy.fmi1 import FMICallException

from test_fmu import FMI2_ERROR, INPUTS, expect_error, outputs, step

LUGRE_MARGIN = 1.05  # transient::lugre::LUGRE_FRICTION_MARGIN, stated in the README


def limits(md):
    return {v.name: (float(v.min) if v.min is not None else -math.inf,
                     float(v.max) if v.max is not None else math.inf)
            for v in md.modelVariables if v.causality == "input"}


def test_every_input_has_a_physical_range_containing_its_start(md):
    lim = limits(md)
    assert set(lim) == set(INPUTS)
    for v in md.modelVariables:
        if v.causality == "input":
            lo, hi = lim[v.name]
            assert math.isfinite(lo) and math.isfinite(hi), v.name
            assert lo <= float(v.start) <= hi, (v.name, v.start, lo, hi)


@pytest.mark.parametrize("name,value", [("mu_scale", 1e300), ("Fz", 1e300), ("vy", 1e300),
                                        ("omega", -1e300), ("vx", 1e5), ("p", 1e12),
                                        ("gamma", 3.0), ("phit", -1e9), ("kappa_in", 1e3),
                                        ("alpha_in", -2.0)])
def test_absurd_finite_inputs_are_refused_and_change_nothing(make, vr, log, name, value):
    fmu = make(f"absurd_{name}")
    before = step(fmu, vr, 0.0, 1e-3)
    expect_error(lambda: fmu.setReal([vr[name]], [value]), log, name)
    assert any("physical range" in m for m in log.errors()), log.text()
    after = step(fmu, vr, 1e-3, 1e-3)
    assert after == before


def test_load_far_above_the_tyres_range_is_refused_at_the_step(make, vr, log):
    fmu = make("fz_cap")
    fz0 = fmu.getReal([vr["Fz0"]])[0]
    fmu.setReal([vr["Fz"]], [min(900e3, 50 * fz0)])   # within the XML range
    expect_error(lambda: fmu.doStep(0.0, 1e-3), log, "FNOMIN")
    o = step(fmu, vr, 0.0, 1e-3, Fz=4000.0)
    assert all(math.isfinite(x) for x in o.values())


def test_relaxation_recovers_after_an_extreme_accepted_step(make, vr, md):
    """vy and omega at their limits for one step, then 2 s of straight running:
    Fy returns to the straight-running value of an unpoisoned twin (the issue:
    vy = 1e300 pinned Fy near -3187 N for 21 s)."""
    lim = limits(md)
    a = make("poison", strings={"transient": "relaxation"})
    b = make("clean", strings={"transient": "relaxation"})
    t, h = 0.0, 1e-3
    step(a, vr, t, h, vy=lim["vy"][1])
    step(b, vr, t, h)
    t += h
    step(a, vr, t, h, omega=lim["omega"][0], vy=lim["vy"][0])
    step(b, vr, t, h)
    t += h
    # Back to the twin's straight-running inputs (the start values, which
    # follow the packaged tyre's free-rolling state).
    a.setReal([vr["vy"], vr["omega"]], [0.0, b.getReal([vr["omega"]])[0]])
    for _ in range(2000):
        oa = step(a, vr, t, h)
        ob = step(b, vr, t, h)
        t += h
    fz = a.getReal([vr["Fz"]])[0]
    assert abs(oa["Fy"] - ob["Fy"]) < 0.01 * fz, (oa["Fy"], ob["Fy"])
    assert abs(oa["Fx"] - ob["Fx"]) < 0.01 * fz, (oa["Fx"], ob["Fx"])


def test_lugre_stays_within_its_friction_limit_under_slip_reversals(make, vr):
    """100 m/s, the wheel speed switching between kappa = +0.2 and -0.2 every
    0.5 ms (steps of 0.1 ms): |Fx| <= 1.05 mux Fz (before: 5 Fz)."""
    fmu = make("lugre_rev", strings={"transient": "lugre"})
    vx, fz = 100.0, 4000.0
    re = fmu.getReal([vr["R0"]])[0] * 0.97  # a rolling radius; kappa follows from omega
    t, h, worst = 0.0, 1e-4, 0.0
    for i in range(4000):
        k = 0.2 if (i // 5) % 2 == 0 else -0.2
        o = step(fmu, vr, t, h, vx=vx, omega=vx * (1 + k) / re, Fz=fz)
        t += h
        worst = max(worst, abs(o["Fx"]) / (o["mux"] * fz))
    assert worst <= LUGRE_MARGIN + 1e-9, worst


def test_turn_slip_at_standstill_in_steady_mode(make, vr):
    """use_mode 112 (turn slip on), vx exactly 0: fmi2OK and finite outputs
    (the issue: fmi2Error whenever vx was 0)."""
    fmu = make("ts0", ints={"use_mode": 112})
    t = 0.0
    for vy, omega, phit in [(0.0, 0.0, 0.0), (0.0, 0.0, 0.5), (0.2, 0.0, -1.0), (0.0, 2.0, 1.0)]:
        o = step(fmu, vr, t, 1e-3, vx=0.0, vy=vy, omega=omega, phit=phit)
        t += 1e-3
        assert all(math.isfinite(x) for x in o.values()), o
        assert abs(o["Fx"]) < 1.5 * 4000 and abs(o["Fy"]) < 1.5 * 4000, o


def set_string_with_timeout(fmu, vr, value, seconds=10.0):
    result = {}

    def run():
        try:
            fmu.setString([vr["tyre_file"]], [value])
            result["ok"] = True
        except FMICallException as e:
            result["status"] = e.status

    th = threading.Thread(target=run, daemon=True)
    start = time.monotonic()
    th.start()
    th.join(seconds)
    return result, time.monotonic() - start, th.is_alive()


def test_tyre_file_refuses_a_fifo_without_blocking(make, vr, log, tmpdir_path):
    fifo = tmpdir_path / "tyre.fifo"
    os.mkfifo(fifo)
    fmu = make("fifo", init=False)
    result, took, alive = set_string_with_timeout(fmu, vr, str(fifo))
    assert not alive, "fmi2SetString blocked on a FIFO"
    assert result.get("status") == FMI2_ERROR and took < 5.0, (result, took)
    assert any("regular file" in m for m in log.errors()), log.text()


def test_tyre_file_refuses_devices_and_huge_files(make, vr, log, tmpdir_path):
    fmu = make("devzero", init=False)
    result, took, alive = set_string_with_timeout(fmu, vr, "/dev/zero")
    assert not alive and result.get("status") == FMI2_ERROR and took < 5.0, (result, took)
    big = tmpdir_path / "big.tir"
    with open(big, "wb") as f:
        f.truncate(64 << 20)   # sparse 64 MiB: refused from its size, never read
    result, took, alive = set_string_with_timeout(fmu, vr, str(big))
    assert not alive and result.get("status") == FMI2_ERROR, result
    assert any("limit" in m for m in log.errors()), log.text()


def test_fmu_state_names_no_file_and_belongs_to_its_tyre(make, vr, log, unzipdir, tmpdir_path):
    src = os.path.join(unzipdir, "resources", "tyre.tir")
    other = tmpdir_path / "other_tyre_marker_name.tir"
    text = open(src).read().replace("FNOMIN", "FNOMIN                 = 4100\n$FNOMIN", 1)
    other.write_text(text)
    a = make("st_a", strings={"tyre_file": str(other)})
    step(a, vr, 0.0, 1e-3, vy=0.3)
    s = a.getFMUstate()
    data = a.serializeFMUstate(s)
    assert b"other_tyre_marker_name" not in bytes(data) and b".tir" not in bytes(data)
    # Same tyre: accepted, bit-identical continuation.
    back = a.deSerializeFMUstate(data)
    a.setFMUstate(back)
    # Another instance with the packaged tyre: refused (hash differs), no file opened.
    b = make("st_b")
    with pytest.raises(FMICallException) as e:
        b.deSerializeFMUstate(data)
    assert e.value.status == FMI2_ERROR
    assert any("another tyre" in m for m in log.errors()), log.text()
    a.freeFMUstate(s)
    a.freeFMUstate(back)


def test_debug_logging_categories_restrict_logging(make, vr, log):
    """A category list restricts logging to it (errors and fatal errors
    always reach the master)."""
    fmu = make("cats")
    fmu.setDebugLogging(True, ["logStatusError"])
    n0 = len(log.messages)
    step(fmu, vr, 0.0, 1e-3)
    fmu.reset()   # a logEvents message when events are on
    cats = {c for _, c, _ in log.messages[n0:]}
    assert cats <= {"logStatusError"}, cats
    expect_error(lambda: fmu.setReal([vr["vx"]], [math.nan]))
    assert any(c == "logStatusError" for _, c, _ in log.messages[n0:]), log.text()
