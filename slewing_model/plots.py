"""Figures like the paper's: load distributions around the bearing (Figs 8-11) and
axial stiffness curves (Fig. 6). Needs matplotlib (not part of the FMU's run time)."""
from __future__ import annotations

from typing import Mapping, Sequence

import numpy as np

QUANTITIES = {
    "interference": ("interference", 1e6, "interference [um]"),
    "load": ("contact_load", 1e-3, "contact load [kN]"),
}


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_distribution(results: Mapping[str, object], path, *, quantity: str = "interference", title: str = "") -> None:
    """Per ball around the bearing, diagonal 1-3 and diagonal 2-4 side by side (paper Figs 8-11).

    Parameters
    ----------
    results : mapping of label -> LoadDistribution
        E.g. ``{"rigid rings": r1, "flexible rings": r2}``.
    path : path of the PNG to write
    quantity : {"interference", "load"}
    title : str
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity = {quantity!r}: must be one of {', '.join(QUANTITIES)}")
    field, scale, label = QUANTITIES[quantity]
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for name, result in results.items():
        values = getattr(result, field) * scale
        ball = np.arange(1, values.shape[0] + 1)
        for k, ax in enumerate(axes):
            column = k if quantity == "interference" else (0, 1)[k]  # Q1 (diag 1), Q2 (diag 2)
            ax.plot(ball, values[:, column], "o-", ms=3, lw=1, label=name)
    for k, ax in enumerate(axes):
        ax.set_title(("contacts 1-3 (diagonal 1)", "contacts 2-4 (diagonal 2)")[k])
        ax.set_xlabel("ball")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel(label)
    axes[0].legend()
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_axial_stiffness(curves: Mapping[str, tuple[Sequence[float], Sequence[float]]], path, *, title: str = "",
                         note: str = "") -> None:
    """Axial load against axial displacement (paper Fig. 6).

    Parameters
    ----------
    curves : mapping of label -> (displacements in m, loads in N)
    note : str
        A caption under the axes (what explains the curves).
    """
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4.5 + 0.16 * note.count("\n") + (0.3 if note else 0.0)))
    for name, (z, f) in curves.items():
        ax.plot(np.asarray(z) * 1e6, np.asarray(f) / 1e3, "o-", ms=3, label=name)
    ax.set_xlabel("axial displacement [um]")
    ax.set_ylabel("axial load [kN]")
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(title)
    if note:
        fig.text(0.01, 0.01, note, fontsize=7, va="bottom", ha="left")
        fig.tight_layout(rect=(0, 0.04 + 0.03 * note.count("\n"), 1, 1))
    else:
        fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
