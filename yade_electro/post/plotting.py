"""Plots of an engine's history (matplotlib, Agg backend; imported only when called).

    from yade_electro.post.plotting import plot_history
    plot_history("electrothermal.csv", "history.png")       # or an engine's .history

The figure has one panel per group of columns present in the history: resistance, current,
power and energy, temperatures. The x axis is ``time`` (thermal time, s) when present, else
``iter``.
"""
from __future__ import annotations

import csv
from typing import Sequence

import numpy as np

__all__ = ["plot_history", "history_columns"]

#: Panels: (title, y label, columns); a panel is drawn when one of its columns is there.
PANELS = (
    ("equivalent resistance", "R_eq [ohm]", ("R_eq",)),
    ("current", "I [A]", ("current",)),
    ("Joule power and energy", "P [W] / E [J]", ("joule_power", "joule_energy", "heat_content")),
    ("temperature", "T [K]", ("T_mean", "T_max", "T_min")),
)


def history_columns(history) -> dict:
    """Columns of a History, a pandas DataFrame or a CSV path, as float arrays."""
    if isinstance(history, str):
        with open(history, newline="") as fh:
            rows = list(csv.DictReader(fh))
        if not rows:
            raise ValueError(f"{history}: no rows to plot")
        return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    if hasattr(history, "rows"):                      # yade_electro.engine.History
        if not history.rows:
            raise ValueError("the history has no rows yet")
        return {k: np.array([float(r[k]) for r in history.rows]) for k in history.rows[0]}
    return {k: np.asarray(history[k], dtype=float) for k in history.columns}   # DataFrame


def plot_history(history, path: str, x: str = None, panels: Sequence = PANELS) -> str:
    """Write a PNG of the history's figures to ``path`` and return the path."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cols = history_columns(history)
    if x is None:
        x = "time" if "time" in cols else "iter"
    drawn = [p for p in panels if any(c in cols for c in p[2])]
    if not drawn:
        raise ValueError(f"nothing to plot: the history has columns {sorted(cols)}")
    fig, axes = plt.subplots(len(drawn), 1, figsize=(6, 2.4 * len(drawn)), sharex=True, squeeze=False)
    for ax, (title, ylabel, names) in zip(axes[:, 0], drawn):
        for name in names:
            if name in cols:
                ax.plot(cols[x], cols[name], ".-", label=name)
        ax.set_title(title, fontsize=10)
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=8)
    axes[-1, 0].set_xlabel(f"{x} [s]" if x in ("time", "mech_time") else x)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
