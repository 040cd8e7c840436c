"""The fixed style of rockdem's figures, the figure a notebook shows inline, and the saver.

Matplotlib only (no xarray, no kernels): the process that draws ``rockdem run``'s plot
(:mod:`rockdem.rocking_plot`) imports this and nothing heavier.
"""

from __future__ import annotations

from pathlib import Path

from matplotlib import rc_context
from matplotlib.figure import Figure

from .cli import MAX_DPI

__all__ = ["STYLE", "InlineFigure", "save_figure"]

STYLE: dict[str, object] = {
    "font.family": "DejaVu Sans",
    "font.size": 9.0,
    "axes.titlesize": 10.0,
    "axes.labelsize": 9.0,
    "legend.fontsize": 8.0,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "lines.linewidth": 1.2,
    "figure.dpi": 100.0,
    "savefig.dpi": 100.0,
    "path.simplify": False,
    "svg.hashsalt": "rockdem",
}
"""Fixed Matplotlib settings (fonts, sizes, dpi) so that images are reproducible."""


class InlineFigure(Figure):
    """A Matplotlib figure that a notebook displays inline as a cell's value, without a prior
    ``import matplotlib.pyplot`` or ``%matplotlib inline`` (IPython calls :meth:`_repr_png_`)."""

    def _repr_png_(self) -> bytes:
        import io

        buf = io.BytesIO()
        with rc_context(STYLE):
            self.savefig(buf, format="png", dpi=STYLE["savefig.dpi"], bbox_inches="tight")
        return buf.getvalue()


def save_figure(fig: Figure, path: str | Path, *, dpi: float | None = None) -> Path:
    """Write a figure as PNG or PDF (by suffix) with the fixed style; returns the path."""
    p = Path(path)
    if p.suffix.lower() not in (".png", ".pdf"):
        raise ValueError(f"output {p}: the suffix must be .png or .pdf")
    if dpi is not None and not (0.0 < float(dpi) <= MAX_DPI):
        raise ValueError(f"dpi = {dpi!r}: give a resolution in (0, {MAX_DPI:g}] dots per inch (or None, the default 100)")
    p.parent.mkdir(parents=True, exist_ok=True)
    with rc_context(STYLE):
        fig.savefig(p, dpi=dpi or STYLE["savefig.dpi"], metadata={"Software": None} if p.suffix == ".png" else None)
    return p
