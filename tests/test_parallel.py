"""The joint law on several threads (``simulate(threads=...)``, kernels.forces._law_pass_parallel)
gives the serial answer bit for bit: every face pair writes only its own entries, and the
resultants, energies, failures and releases are added up in pair order afterwards.

The cases are collapses, so that every path of the law runs on the threads: bonds failing in
tension and shear, sub-contacts opening and closing, blended pairs asking for a detection, edge
pairs, implicit SP dashpots. They are chaotic, so any difference in the last bit of one force
would grow into a visible one by the end.
"""

import importlib.util
import subprocess
import sys
from pathlib import Path

import numba
import numpy as np
import pytest

from rockdem.materials import JointMaterial
from rockdem.model import Damping, ModelBuilder
from rockdem.simulation import PARALLEL_MIN_BLOCKS, simulate

_spec = importlib.util.spec_from_file_location(
    "collapse_scenarios", Path(__file__).resolve().parents[1] / "benchmarks" / "collapse_scenarios.py"
)
scenarios = importlib.util.module_from_spec(_spec)
sys.modules["collapse_scenarios"] = scenarios
_spec.loader.exec_module(scenarios)

needs_two = pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="Numba has a single thread here")

def _same(a, b) -> None:
    """Every recorded variable equal, bit for bit (NaN where NaN)."""
    assert set(a.data_vars) == set(b.data_vars)
    for name in a.data_vars:
        x, y = a[name].values, b[name].values
        if x.dtype.kind in "fc":
            assert np.array_equal(x, y, equal_nan=True), name
        else:
            assert np.array_equal(x, y), name
    assert a.attrs["steps"] == b.attrs["steps"]
    assert a.attrs["sub_contact_updates"] == b.attrs["sub_contact_updates"]
    assert np.ptp(a.block_position.values) > 0.0


def _sp_stack():
    """Three stacked blocks with SP damping (implicit dashpots), the top one rocking off a tilt."""
    b = ModelBuilder(points=(2, 3))
    b.set_material("block", "block", JointMaterial(kn=1e9, friction_angle=35))
    b.set_material("block", "ground", JointMaterial(kn=1e9, friction_angle=35))
    b.set_material("ground", "ground", JointMaterial(kn=1e9))
    b.add_box(2.0, 2.0, 0.2, base_center=(0, 0, -0.2), driven=True, name="ground", group="ground")
    for k in range(3):
        b.add_box(0.2, 0.5, 0.4, base_center=(0.02 * k, 0, 0.4 * k), density=2000, group="block", name=f"b{k}")
    b.tilt("b2", 0.9)
    return b.finalize(damping=Damping(beta=0.002))


@needs_two
@pytest.mark.parametrize("case", ["cascade_wall", "parapet_earthquake", "random_pile"])
def test_threads_give_the_serial_answer_bit_for_bit(case):
    sc = getattr(scenarios, case)(short=True)
    duration = min(sc.duration, 0.8)
    serial = simulate(sc.model, duration, record_interval=0.01, progress=False, threads=1)
    threaded = simulate(sc.model, duration, record_interval=0.01, progress=False, threads=2)
    assert serial.attrs["threads"] == 1 and threaded.attrs["threads"] == 2
    _same(serial, threaded)


@needs_two
def test_threads_with_implicit_dashpots():
    model = _sp_stack()
    serial = simulate(model, 0.5, record_interval=0.01, progress=False, threads=1)
    threaded = simulate(model, 0.5, record_interval=0.01, progress=False, threads=2)
    assert serial.attrs["dashpots"] == "implicit"
    assert np.ptp(serial.block_rotation.values[:, model.block_id("b2"), :]) > 0.05  # it rocks
    _same(serial, threaded)


def test_small_models_run_serially_by_default():
    model = _sp_stack()
    assert model.block_count < PARALLEL_MIN_BLOCKS
    assert simulate(model, 0.01, progress=False).attrs["threads"] == 1


@pytest.mark.parametrize("bad", [0, -2, 1.5, True, "2"])
def test_bad_thread_counts_are_refused(bad):
    with pytest.raises(ValueError, match="threads"):
        simulate(_sp_stack(), 0.01, progress=False, threads=bad)


def test_more_threads_than_numba_has_are_refused():
    with pytest.raises(ValueError, match="NUMBA_NUM_THREADS"):
        simulate(_sp_stack(), 0.01, progress=False, threads=numba.config.NUMBA_NUM_THREADS + 1)


_LAW_CODE_RUN = """
import hashlib, sys, warnings
import numpy as np
import rockdem.simulation as sim
sys.path.insert(0, sys.argv[2])
from test_parallel import _sp_stack
if sys.argv[1] == "copy":
    sim._load_law_first = lambda model: None
model = _sp_stack()
warnings.simplefilter("error")  # the kernels' loading run (undamped) must not warn the user
ds = sim.simulate(model, 0.5, record_interval=0.01, progress=False, threads=1)
state = ds.block_position.values.tobytes() + ds.block_quaternion.values.tobytes()
print(ds.attrs["steps"], np.ptp(ds.block_rotation.values[:, model.block_id("b2"), :]), hashlib.sha256(state).hexdigest())
"""


def test_the_laws_own_code_and_the_copy_in_advance_give_the_same_answer():
    """Each run loads the joint law's own compiled code before the kernels that hold copies of it
    (simulation._load_law_first: the copy inside a cached ``advance`` ran the 1000-brick wall 1.3
    times slower). Both compute the same answer bit for bit, and the loading is silent. Fresh
    processes: which code a call runs is settled when the kernels are first loaded."""
    out = {}
    for which in ("own", "copy"):
        run = subprocess.run([sys.executable, "-c", _LAW_CODE_RUN, which, str(Path(__file__).parent)], capture_output=True, text=True,
                             timeout=900)
        assert run.returncode == 0, run.stderr[-2000:]
        out[which] = run.stdout.split()
    assert out["own"] == out["copy"]
    assert float(out["own"][1]) > 0.05  # the top block rocks
