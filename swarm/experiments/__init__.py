"""The papers' experiments: one folder per paper, each declaring its experiments (EXPERIMENTS,
swarm.core.registry.ExperimentSpec entries) for `swarm experiment NAME`."""

from swarm.core.registry import ExperimentSpec, PaperSpec, Registry

EXPERIMENTS: Registry[ExperimentSpec] = Registry("experiment", "swarm.experiments", "EXPERIMENTS")
PAPERS: Registry[PaperSpec] = Registry("paper", "swarm.experiments", "PAPER")
