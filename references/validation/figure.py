"""The validation pages' figures: matplotlib without a display, each written where its script is told."""
from __future__ import annotations

from pathlib import Path


def pyplot():
    """matplotlib's pyplot on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, out) -> int:
    """Lay ``fig`` out, write it to ``out`` (its folder made), say where; 0, the script's exit status."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"figure: {out}")
    return 0
