"""Start values follow the packaged tyre (issue #18): an FMU run untouched by the
master (no start values set, fmpy's default simulate_fmu) sees the packaged tyre
free rolling at its nominal load: |kappa| < 1e-6 and |Fx| < 2 % of Fz.

Packages the built-in tyre and ../shared/data/tir/FSAE_Defaults.tir (skipped
with a message when ../shared is absent) with the built `tyrekit` binary.
Bounds: kappa is zero by construction (omega = vx/Re at the model's own Re,
iterated to round-off), 1e-6 is the issue's bound; Fx at kappa = 0 is only the
zero-slip offset SVx/SHx of the file, well below the issue's 2 % of Fz.
"""

import os
import pathlib
import subprocess

import pytest
from fmpy import read_model_description, simulate_fmu

ROOT = pathlib.Path(__file__).resolve().parents[2]
TARGET = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
if not TARGET.is_absolute():
    TARGET = ROOT / TARGET
TYREKIT = TARGET / "release" / "tyrekit"
FSAE = ROOT.parent / "shared" / "data" / "tir" / "FSAE_Defaults.tir"


def package(tmp_path, tir=None):
    if not TYREKIT.exists():
        subprocess.run(["cargo", "build", "--release", "--bin", "tyrekit"], cwd=ROOT, check=True)
    out = tmp_path / "tyre.fmu"
    cmd = [str(TYREKIT), "package", "--out", str(out)]
    if tir is not None:
        cmd += ["--tir", str(tir)]
    subprocess.run(cmd, check=True, cwd=tmp_path)
    return out


@pytest.mark.parametrize("tyre", ["builtin", "FSAE_Defaults"])
def test_untouched_start_values_roll_freely(tmp_path, tyre):
    tir = None
    if tyre == "FSAE_Defaults":
        if not FSAE.exists():
            pytest.skip(f"{FSAE} not found (../shared absent)")
        tir = FSAE
    fmu = package(tmp_path, tir)
    md = read_model_description(str(fmu))
    start = {v.name: v.start for v in md.modelVariables}
    res = simulate_fmu(str(fmu), stop_time=0.1, output_interval=0.01,
                       output=["kappa", "Fx"])
    fz = float(start["Fz"])
    assert fz > 0
    kappa = abs(res["kappa"]).max()
    fx = abs(res["Fx"]).max()
    assert kappa < 1e-6, f"{tyre}: |kappa| = {kappa} at the start state"
    assert fx < 0.02 * fz, f"{tyre}: |Fx| = {fx} N at Fz = {fz} N"
