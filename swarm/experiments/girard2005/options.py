"""The girard2005 experiments' own command-line values: --bg settings, --ratios and --sizes."""

from __future__ import annotations

import argparse
import tomllib


def ratios(text: str) -> tuple[float, ...]:
    from swarm.experiments.girard2005.bg import RATIOS

    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if not values or any(v not in RATIOS for v in values):
        raise argparse.ArgumentTypeError(f"expected some of {','.join(f'{r:g}' for r in RATIOS)} (the tmaze-R "
                                         f"scenarios), got {text}")  # fmt: skip
    return values


def bg_setting(text: str) -> tuple[str, object]:
    """KEY=VALUE, the value a TOML literal (0.5, true, "fear"); navigation.KEY names a [bg.navigation] field."""
    key, sep, value = text.partition("=")
    try:
        parsed = tomllib.loads(f"v = {value}")["v"] if sep and key else None
    except tomllib.TOMLDecodeError:
        parsed = None
    if parsed is None or isinstance(parsed, (dict, list)):
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE (e.g. dorsal_threshold=0.8, navigation.anchor=0.2), "
                                         f"got {text}")  # fmt: skip
    return key.strip(), parsed


def bg_table(settings: list[tuple[str, object]] | None) -> dict:
    """--bg settings as a [bg] table (navigation.KEY into its [bg.navigation] table)."""
    table: dict = {}
    for key, value in settings or ():
        if key.startswith("navigation."):
            table.setdefault("navigation", {})[key.removeprefix("navigation.")] = value
        else:
            table[key] = value
    return table


def sizes(text: str) -> tuple[int, ...]:
    from swarm.experiments.girard2005.colony import NEST

    try:
        values = tuple(int(v) for v in text.split(","))
    except ValueError:
        values = ()
    if not values or any(not 1 <= v <= len(NEST) for v in values):
        raise argparse.ArgumentTypeError(f"expected colony sizes from 1 to {len(NEST)} (the nest's places), "
                                         f"got {text}")  # fmt: skip
    return values
