"""A scenario's floor as a picture, before anything runs (`swarm check FILE --png`): the arena's
walls, zones, obstacles, resources, fixed starts and goals in metres; the grid's walls, base and
resources cell by cell.  What a user checks by eye after writing a floor by hand."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def draw_floor(scenario, path: Path) -> Path:
    from swarm.core.plots import plot_writer

    path = Path(path)
    plt, save, _ = plot_writer(path.parent)
    fig, ax = plt.subplots(figsize=(6, 6))
    (_draw_arena if hasattr(scenario, "walls") else _draw_grid)(plt, ax, scenario)
    ax.set_title(f"{scenario.name}: {getattr(scenario, 'description', '') or 'floor'}"[:90], fontsize=9)
    save(fig, path.name)
    return path


def _draw_arena(plt, ax, s) -> None:
    for wall in s.walls:
        x0, y0, x1, y1 = wall.coords
        colour = np.array(wall.colour) / 255
        if wall.shape == "rect":
            ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, color=colour, lw=0))
        else:
            ax.plot([x0, x1], [y0, y1], color=colour, lw=2)
    for z in s.zones:
        if z.shape == "rect":
            x0, y0, x1, y1 = z.coords
            ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, fill=False, ls="--", ec="tab:green"))
            ax.annotate(z.name or z.kind, (x0, y1), fontsize=7, color="tab:green")
        else:
            cx, cy, r = z.coords
            ax.add_patch(plt.Circle((cx, cy), r, fill=False, ls="--", ec="tab:green"))
            ax.annotate(z.name or z.kind, (cx, cy + r), fontsize=7, color="tab:green", ha="center")
    for o in s.obstacles:
        x0, y0, x1, y1 = o.rect
        ax.add_patch(plt.Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor=np.array(o.colour) / 255, edgecolor="k",
                                   lw=0.5, alpha=0.9))  # fmt: skip
        if o.name:
            ax.annotate(o.name, ((x0 + x1) / 2, y1), ha="center", va="bottom", fontsize=7)
    for g in s.groups:
        for x, y, theta in g.starts or ():
            radius = g.robot.radius
            ax.add_patch(plt.Circle((x, y), radius, color="tab:blue", alpha=0.7))
            ax.plot([x, x + 2 * radius * np.cos(theta)], [y, y + 2 * radius * np.sin(theta)], color="k", lw=1)
        for gx, gy in g.goals or ():
            ax.plot(gx, gy, "x", color="k")
    ax.set(xlim=(0, s.size[0]), ylim=(0, s.size[1]), aspect="equal", xlabel="x (m)", ylabel="y (m)")


def _draw_grid(plt, ax, s) -> None:
    layout = s.layout()
    image = np.where(layout.obstacles, 0.2, 1.0)[..., None] * np.ones(3)
    image[layout.resources > 0] = (0.95, 0.75, 0.2)
    image[layout.base] = (0.2, 0.4, 0.9)
    ax.imshow(image, interpolation="nearest")
    ax.set(xlabel="column", ylabel="row")
