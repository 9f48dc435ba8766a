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
        save_figure(fig, path, dpi=120)
        written.append(path)

    return plt, save, written


def pyplot():
    """matplotlib's pyplot drawing to files (the Agg backend: no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: Path, dpi: int = 110) -> None:
    """`fig` to `path`, laid out, then closed (a long experiment draws many)."""
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
