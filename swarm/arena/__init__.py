"""The arena's runners and the four papers' arena experiments: the in-process engine, the scenario
section, and one module per experiment family."""
