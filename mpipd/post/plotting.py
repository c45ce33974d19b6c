"""Matplotlib set-up shared by the figure modules (headless Agg backend)."""
from __future__ import annotations

from pathlib import Path


def pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"font.size": 9, "axes.titlesize": 9, "figure.titlesize": 10})
    return plt


def save(fig, path) -> str:
    plt = pyplot()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path.name


def borehole(ax, model):
    """Outline the borehole wall and the outer boundary (mm)."""
    plt = pyplot()
    for r in (model.r_wall, model.r_out):
        ax.add_patch(plt.Circle((model.center[0] * 1e3, model.center[1] * 1e3), r * 1e3,
                                fill=False, lw=0.6, color="0.4"))
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")


def plain_log(ax):
    """Plain numbers (not 10^k) on the ticks of log axes."""
    from matplotlib.ticker import FuncFormatter
    fmt = FuncFormatter(lambda v, _: f"{v:g}")
    for axis in (ax.xaxis, ax.yaxis):
        if axis.get_scale() == "log":
            axis.set_major_formatter(fmt)
            axis.set_minor_formatter(FuncFormatter(
                lambda v, _: f"{v:g}" if str(f"{v:g}")[0] in "25" else ""))


def log_axes(ax, xlabel: str, ylabel: str, logy: bool = False):
    """A log x (and optionally log y) axis with plain tick numbers, a grid and a legend."""
    ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=7)
    plain_log(ax)
