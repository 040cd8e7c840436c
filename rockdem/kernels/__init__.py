"""Numba kernels: pure functions over flat arrays, grouped by pipeline stage.

- ``rotation``: quaternion and rotation helpers.
- ``detect``: broad phase (bounding boxes) and common-plane narrow phase, persistent point state.
- ``contact``: the joint law per sub-contact (Mohr-Coulomb, tension cut-off, SP dashpots).
- ``step``: forces, central-difference integration, recording; the per-chunk time loop.
"""
