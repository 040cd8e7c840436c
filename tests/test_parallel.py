"""Parallel contact passes (issue 12, item 4): the same answer, bit for bit, on any thread count."""

import numba
import numpy as np
import pytest

from rockdem.case import parse_case
from rockdem.kernels.forces import PARALLEL_PAIRS
from rockdem.kernels.step import advance
from rockdem.simulation import PARALLEL_BLOCKS, simulate

pytestmark = pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="one Numba thread on this machine")


def _cascade_wall():
    # A weakly bonded running-bond wall shaken to failure: bonds fail in tension and shear, contacts
    # open and close, bricks slide (every branch of the joint law and the release pass).
    weak = {"kn": 2e9, "friction_angle_deg": 31.0, "cohesion": 5e3, "tension": 5e3}
    return parse_case({
        "run": {"duration": 2.5, "record_interval": 0.01},
        "specimen": {"type": "wall", "courses": 8, "bricks_per_course": 5, "joint": weak,
                     "base": {"kn": 2e9, "friction_angle_deg": 31.0}},
        "loading": {"type": "earthquake", "record": "elcentro-rsn6", "scale": 4.0, "direction": [1.0, 0.0, 0.0],
                    "mode": "foundation"},
        "damping": {"alpha": 2.0},
    }).model


def test_parallel_contact_passes_give_the_serial_answer_bit_for_bit():
    model = _cascade_wall()
    assert model.block_count >= PARALLEL_BLOCKS
    runs = {}
    before = numba.get_num_threads()
    try:
        for threads in (1, 2):
            numba.set_num_threads(threads)
            runs[threads] = simulate(model, 2.5, record_interval=0.01, progress=False)
    finally:
        numba.set_num_threads(before)
    serial, parallel = runs[1], runs[2]
    # the two-thread run used the parallel variant, on enough pairs, and the cascade did happen
    assert any("Parallel" in str(sig) for sig in advance.signatures)
    assert int(serial.contacts_active.max()) > PARALLEL_PAIRS
    assert int(serial.contacts_failed_tension[-1]) + int(serial.contacts_failed_shear[-1]) > 10
    for name in serial.data_vars:
        a, b = serial[name].values, parallel[name].values
        if a.dtype.kind in "fiub":
            assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), name
