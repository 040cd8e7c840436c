"""Numba kernels: pure functions over flat arrays, grouped by pipeline stage.

- ``rotation``: quaternion and rotation helpers.
- ``detect``: broad phase (bounding boxes) and common-plane narrow phase, persistent point state.
- ``contact``: the joint law per sub-contact (Mohr-Coulomb, tension cut-off, SP dashpots).
- ``step``: forces, central-difference integration, recording; the per-chunk time loop.

Every kernel is compiled without Numba's reference counting (``_nrt=False``) and allocates
nothing: the arrays it works on are owned by the Python caller for the whole call. With counting
on, each call of a kernel with the model, state and scratch tuples counted their ~150 arrays in
and out (two atomic operations each): 90 % of a step for small models (the Table 2 block, 10 s of
SP free rocking: 0.68 s -> 0.044 s). It also makes any heap allocation inside the step a compile
error instead of a hidden cost (a kernel called from ``advance`` is compiled with its flags).
"""

import hashlib
import os
from pathlib import Path


def _drop_stale_cache() -> None:
    """Delete Numba's on-disk cache of these kernels when any kernel source changed.

    Numba checks only the source file of the function it loads: ``step.advance`` cached before an
    edit of ``faces.py`` keeps the old inlined code of ``faces.py`` (a silent wrong answer after a
    ``git pull``). A hash of all kernel sources is kept beside the cache; a mismatch empties it.
    With ``NUMBA_CACHE_DIR`` set the cache lives elsewhere and is left alone.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return
    here = Path(__file__).parent
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in sorted(here.glob("*.py")))).hexdigest()
    cache = here / "__pycache__"
    stamp = cache / "kernel-sources.sha256"
    try:
        if stamp.read_text() == digest:
            return
        for f in cache.glob("*.nb[ic]"):
            f.unlink(missing_ok=True)
    except OSError:
        pass
    try:
        cache.mkdir(exist_ok=True)
        stamp.write_text(digest)
    except OSError:  # a read-only install: Numba then caches elsewhere or not at all
        pass


_drop_stale_cache()
