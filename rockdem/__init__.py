"""rockdem: 3D rigid-block discrete element method for rocking masonry blocks.

The main API is importable from the package root (loaded on first use, so ``import rockdem`` stays
fast): ``ModelBuilder``, ``Damping``, ``Motion``, ``JointMaterial``, ``box``, ``convex_hull``,
``simulate``, ``save``, ``load``, the specimen builders (``stacked_blocks``, ``brick_wall``,
``parapet``, ``facade``, ``two_block_wall``), loading (``apply_earthquake``, ``pushover``,
``apply_rod_pushover``, ``capacity_curve``, ``load_carried``, ``read_record``), ``advise``,
``summarize_result``, ``fallen_blocks``,
``housner_rock``, automatic SP damping (``critical_betas``, ``RestitutionTarget``; ``Damping(beta="auto")``
and ``Damping(beta="critical")``), case files (``load_case``, ``parse_case``, ``run_case``) and studies
(``RunSpec``, ``execute``, ``calibrate``, ``run_ida``).
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

_API = {
    "ModelBuilder": "model", "Damping": "model", "Motion": "model", "Model": "model",
    "JointMaterial": "materials", "box": "geometry", "convex_hull": "geometry",
    "simulate": "simulation", "save": "results", "load": "results",
    "stacked_blocks": "specimens", "brick_wall": "specimens", "parapet": "specimens",
    "facade": "specimens", "two_block_wall": "specimens",
    "apply_earthquake": "loading", "pushover": "loading", "apply_rod_pushover": "loading",
    "capacity_curve": "loading", "load_carried": "loading", "read_record": "records",
    "advise": "advisor", "summarize_result": "analysis", "fallen_blocks": "analysis",
    "critical_betas": "interfaces", "RestitutionTarget": "beta_choice",
    "load_case": "case", "parse_case": "case", "run_case": "run_cli",
    "RunSpec": "studies", "execute": "studies", "calibrate": "calibration", "run_ida": "fragility",
}
_ALIASES = {"housner_rock": ("housner", "rock")}

__all__ = ["__version__", *_API, *_ALIASES]


def __getattr__(name: str) -> Any:
    if name in _API:
        return getattr(importlib.import_module(f".{_API[name]}", __name__), name)
    if name in _ALIASES:
        mod, attr = _ALIASES[name]
        return getattr(importlib.import_module(f".{mod}", __name__), attr)
    raise AttributeError(f"module 'rockdem' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
