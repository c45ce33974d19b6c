"""Maps on sections and on the axial plane.

* Fig. 9  — damage phi on the two end faces at the pattern times;
* Fig. 11 — damage phi on the sections 5 mm from the detonation end, at
  mid-thickness and 5 mm from the far end, at the pattern times;
* Fig. 13 — failure mode on the end faces and mid-thickness at the last frame;
* Fig. 7  — pressure on the axial x–z plane at a few times (explosive and rock);
* Figs. 19, 22 — one section of several runs side by side (``compare``).

Sections are drawn on their lattice (one pixel per point, white off the rock; a
zoned rock draws each zone on its own lattice), viewed from +z; the borehole wall
and the outer boundary are outlined.
"""
from __future__ import annotations

import numpy as np

from mpipd.kernels.layout import MODE_LABELS

from .plotting import borehole, pyplot, save
from .sections import NAMED, section_images

MODE_COLORS = ("#d9d9d9", "#d62728", "#1f77b4", "#2ca02c")


def _draw_section(ax, sec, key, model, **style):
    """Every zone's lattice image of a section on ``ax``; the last image drawn."""
    im, exts = None, []
    for img, ext in section_images(sec, key, model.center, model.r_out):
        im = ax.imshow(img, origin="lower", extent=ext, interpolation="nearest", **style)
        exts.append(ext)
    if exts:
        e = np.array(exts)
        ax.set_xlim(e[:, 0].min(), e[:, 1].max())
        ax.set_ylim(e[:, 2].min(), e[:, 3].max())
    return im


def _damage_panel(ax, sec, key, model, title):
    im = _draw_section(ax, sec, key, model, cmap="inferno", vmin=0.0, vmax=1.0)
    borehole(ax, model)
    ax.set_title(title)
    return im


#: the rows of Fig. 11's damage picture (sections.NAMED: 5 mm, mid-thickness, T - 5 mm)
FIG11_ROWS = (NAMED[1], NAMED[2], NAMED[3])


def _damage_grid(data, model, times, frames, rows, label, what, out) -> str:
    """rows = section names, columns = frames."""
    plt = pyplot()
    lv = data["levels"]
    rows = [n for n in rows if n in lv]
    fig, axes = plt.subplots(len(rows), len(frames), squeeze=False,
                             figsize=(2.6 * len(frames) + 0.8, 2.6 * len(rows) + 0.6))
    im = None
    for i, name in enumerate(rows):
        sec = data["sections"][name]
        for j, k in enumerate(frames):
            if ("damage", k) not in sec:
                axes[i, j].set_axis_off()
                continue
            im = _damage_panel(axes[i, j], sec, ("damage", k), model,
                               f"t = {times[k] * 1e6:.2f} µs")
            axes[i, j].set_ylabel(f"{name}, z = {lv[name] * 1e3:.2f} mm\ny (mm)" if j == 0
                                  else "y (mm)")
    if im is not None:
        fig.colorbar(im, ax=axes, shrink=0.8, label="damage φ (–)")
    fig.suptitle(f"{label}: {what}")
    return save(fig, out)


def fracture_pattern(data, model, times, frames, label, out) -> str:
    """Fig. 9: rows = the two end faces (viewed from +z), columns = the pattern frames."""
    return _damage_grid(data, model, times, frames, (NAMED[0], NAMED[4]), label,
                        "damage φ on the end faces (cf. paper Fig. 9)", out)


def fracture_sections(data, model, times, frames, label, out) -> str:
    """Fig. 11: the sections 5 mm from the detonation end, mid-thickness and 5 mm from
    the far end (45 mm in the paper's 50 mm specimen), columns = the pattern frames."""
    return _damage_grid(data, model, times, frames, (NAMED[1], NAMED[2], NAMED[3]), label,
                        "damage φ on cross-sections through the thickness (cf. paper Fig. 11)",
                        out)


def failure_modes(data, model, times, last, label, out) -> str:
    """Fig. 13: failure mode on the end faces and mid-thickness."""
    plt = pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch
    lv = data["levels"]
    names = [n for n in (NAMED[0], NAMED[2], NAMED[4]) if n in lv]
    cmap = ListedColormap(MODE_COLORS)
    norm = BoundaryNorm(np.arange(-0.5, len(MODE_COLORS)), cmap.N)    # one bin per mode code
    fig, axes = plt.subplots(1, len(names), squeeze=False, figsize=(3.0 * len(names), 3.9))
    for j, name in enumerate(names):
        sec = data["sections"][name]
        _draw_section(axes[0, j], sec, ("failure_mode", last), model, cmap=cmap, norm=norm)
        borehole(axes[0, j], model)
        axes[0, j].set_title(f"{name}, z = {lv[name] * 1e3:.2f} mm")
    fig.legend(handles=[Patch(color=c, label=m) for c, m in zip(MODE_COLORS, MODE_LABELS)],
               loc="lower center", ncol=4, frameon=False)
    fig.suptitle(f"{label}: failure mode at t = {times[last] * 1e6:.2f} µs (cf. paper Fig. 13)")
    fig.tight_layout(rect=(0, 0.07, 1, 0.95))
    return save(fig, out)


def plane_pressure(plane, model, times, frames, label, out) -> str:
    """Fig. 7: pressure on the axial x–z plane (log colour scale from 1 MPa)."""
    plt = pyplot()
    from matplotlib.colors import LogNorm
    fig, axes = plt.subplots(1, len(frames), squeeze=False,
                             figsize=(2.4 * len(frames) + 1.0, 3.6), sharey=True)
    vmax = max(float(np.nanmax(plane[k])) for k in frames) / 1e6
    vmax = max(vmax, 10.0)
    norm = LogNorm(vmin=1.0, vmax=vmax)
    dx = model.dx
    xs, zs = plane["x"], plane["z"]
    i = np.floor((xs - xs.min()) / dx + 0.5).astype(int)
    j = np.floor((zs - zs.min()) / dx + 0.5).astype(int)
    i0 = i.min()
    im = None
    for a, k in enumerate(frames):
        img = np.full((j.max() + 1, i.max() - i0 + 1), np.nan)
        img[j, i - i0] = np.maximum(plane[k] / 1e6, 1e-3)
        ext = [(xs.min() - dx / 2) * 1e3, (xs.max() + dx / 2) * 1e3,
               (zs.min() - dx / 2) * 1e3, (zs.max() + dx / 2) * 1e3]
        im = axes[0, a].imshow(img, origin="lower", extent=ext, cmap="viridis", norm=norm,
                               interpolation="nearest", aspect="auto")
        axes[0, a].set_title(f"t = {times[k] * 1e6:.2f} µs")
        axes[0, a].set_xlabel("x (mm)")
    axes[0, 0].set_ylabel("z (mm), detonation end at the bottom")
    fig.colorbar(im, ax=axes, shrink=0.85, label="pressure (MPa, log scale; ≤ 1 MPa dark)")
    fig.suptitle(f"{label}: pressure on the axial plane y ≈ 0 (cf. paper Fig. 7)")
    return save(fig, out)


def compare_patterns(entries, section, out) -> str:
    """Figs. 19, 22: the damage on one section of each run at its last frame.
    ``entries`` = [(label, model, sec, key, t_us, z_mm)]."""
    plt = pyplot()
    n = len(entries)
    cols = min(n, 3)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, squeeze=False, figsize=(3.2 * cols + 0.8, 3.3 * rows))
    im = None
    for a, (label, model, sec, key, t_us, z_mm) in enumerate(entries):
        ax = axes[a // cols, a % cols]
        if sec is None or key not in sec:
            ax.set_axis_off()
            ax.set_title(f"{label}: no damage field")
            continue
        im = _damage_panel(ax, sec, key, model, f"{label}\nz = {z_mm:.2f} mm, t = {t_us:.2f} µs")
    for a in range(n, rows * cols):
        axes[a // cols, a % cols].set_axis_off()
    if im is not None:
        fig.colorbar(im, ax=axes, shrink=0.8, label="damage φ (–)")
    fig.suptitle(f"damage φ on the {section} of each run (cf. paper Figs. 19, 22)")
    return save(fig, out)
