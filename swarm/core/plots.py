"""Plots written to files, the same way by every report and experiment (no display needed)."""

from __future__ import annotations

from pathlib import Path


def plot_writer(out: Path):
    """(pyplot, save(fig, name), the list of files saved) for plots into `out`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []

    def save(fig, name: str) -> None:
        path = out / name
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)
        written.append(path)

    return plt, save, written
