"""Fixtures for the FMU tests: the packaged FMU, an unpacked copy, instances with a
message-capturing logger, and the library's own evaluation (examples/mf_reference).

The FMU is target/fmu/TyreKit.fmu (CARGO_TARGET_DIR respected); it and the
reference helper are built with cargo when missing, so `pytest tests/python`
works on its own (scripts/test-all builds them first anyway).
"""

import ctypes
import os
import pathlib
import shutil
import subprocess
import tempfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.logging import addLoggerProxy

ROOT = pathlib.Path(__file__).resolve().parents[2]
TARGET = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
if not TARGET.is_absolute():
    TARGET = ROOT / TARGET
FMU = TARGET / "fmu" / "TyreKit.fmu"
REFERENCE = TARGET / "release" / "examples" / "mf_reference"


def _cargo(*args):
    subprocess.run(["cargo", *args], cwd=ROOT, check=True)


@pytest.fixture(scope="session")
def fmu_path():
    if not FMU.exists():
        _cargo("run", "--release", "--quiet", "--bin", "tyrekit", "--", "package")
    return str(FMU)


@pytest.fixture(scope="session")
def md(fmu_path):
    return read_model_description(fmu_path)


@pytest.fixture(scope="session")
def vr(md):
    return {v.name: v.valueReference for v in md.modelVariables}


@pytest.fixture(scope="session")
def unzipdir(fmu_path):
    d = extract(fmu_path)
    yield d
    shutil.rmtree(d, ignore_errors=True)


class Log:
    """fmi2CallbackFunctions whose logger records (status, category, message)."""

    def __init__(self):
        self.messages = []

        def log_message(env, instance, status, category, message):
            self.messages.append(
                (status, category.decode(errors="replace"), message.decode(errors="replace"))
            )

        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(log_message)
        libc = ctypes.CDLL(None)
        libc.calloc.restype = ctypes.c_void_p
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(lambda n, s: libc.calloc(n, s))
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(lambda p: libc.free(ctypes.c_void_p(p)))
        # fmpy's C proxy formats the variadic call and forwards the final text.
        addLoggerProxy(ctypes.byref(self.callbacks))

    def text(self):
        return "\n".join(f"[{c}] {m}" for _, c, m in self.messages)

    def errors(self):
        return [m for s, c, m in self.messages if s >= 3]


@pytest.fixture
def log():
    return Log()


@pytest.fixture
def make(md, unzipdir, log):
    """make(name, strings={}, ints={}, init=True): a slave, optionally initialized."""
    made = []

    def factory(name="t", strings=None, ints=None, reals=None, init=True, guid=None, directory=None):
        fmu = FMU2Slave(
            guid=guid or md.guid,
            unzipDirectory=directory or unzipdir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        fmu.instantiate(callbacks=log.callbacks)
        made.append(fmu)
        vrs = {v.name: v.valueReference for v in md.modelVariables}
        for k, v in (strings or {}).items():
            fmu.setString([vrs[k]], [v])
        for k, v in (ints or {}).items():
            fmu.setInteger([vrs[k]], [v])
        if init:
            fmu.setupExperiment(startTime=0.0)
            fmu.enterInitializationMode()
            for k, v in (reals or {}).items():
                fmu.setReal([vrs[k]], [v])
            fmu.exitInitializationMode()
        return fmu

    yield factory
    for fmu in made:
        try:
            fmu.fmi2FreeInstance(fmu.component)
        except Exception:
            pass


@pytest.fixture(scope="session")
def reference(unzipdir):
    """reference(rows, use_mode=111) -> array of Fx,Fy,Mx,My,Mz from Tyre::evaluate
    of the very tyre file the FMU loads (resources/tyre.tir of the package).

    rows: N x 8 array in MFeval's order Fz, kappa, alpha, gamma, phit, Vx, P, omega.
    """
    tir = os.path.join(unzipdir, "resources", "tyre.tir")
    # Always ask cargo: a no-op when fresh, and a stale helper would judge the
    # file with an old reader.
    _cargo("build", "--release", "--quiet", "--example", "mf_reference")

    def run(rows, use_mode=111):
        text = "Fz,kappa,alpha,gamma,phit,Vx,P,omega\n" + "\n".join(
            ",".join(repr(float(x)) for x in r) for r in rows
        )
        out = subprocess.run(
            [str(REFERENCE), "eval", str(use_mode), tir], input=text, capture_output=True, text=True, check=True
        ).stdout
        return np.array([[float(x) for x in line.split(",")] for line in out.splitlines()[1:]])

    return run


@pytest.fixture(scope="session")
def check_tir():
    """check_tir(path) -> None if the library's reader accepts the file, else its message."""
    # Always ask cargo: a no-op when fresh, and a stale helper would judge the
    # file with an old reader.
    _cargo("build", "--release", "--quiet", "--example", "mf_reference")

    def run(path):
        r = subprocess.run([str(REFERENCE), "check-tir", str(path)], capture_output=True, text=True)
        return None if r.returncode == 0 else r.stderr.strip()

    return run


@pytest.fixture
def tmpdir_path():
    d = tempfile.mkdtemp(prefix="tyrekit-fmu-test-")
    yield pathlib.Path(d)
    shutil.rmtree(d, ignore_errors=True)
