"""`swarm reproduce`: every paper's report from its registry entry, on confirmation seeds only, every
claim with n, a test and a verdict by the protocol's rule."""

from __future__ import annotations

import csv
import re

import pytest

from swarm.core.registry import resolve
from swarm.experiments import PAPERS
from swarm.experiments.protocol import CONFIRMATION_SEEDS, NOT_REPRODUCED, REPRODUCED, REVERSED, SAME_DIRECTION

VERDICTS = {REPRODUCED, SAME_DIRECTION, NOT_REPRODUCED, REVERSED, "–"}
# Simulated time a test's quick run may cut further: girard2005's survival and mapping runs end at 10 min, not 20
# (the same claims, each with its test and a p-value; at 5 min the maps are too short for exp. 2.1 to vary);
# billing2015's large-maze runs at 750 steps, not 1000 (the same summary; at 500 no run reaches its goal, and
# the path-ratio ANOVA has nothing to compare)
SHORTER = {"girard2005": {"QUICK_SECONDS": 600.0}, "billing2015": {"QUICK_CASE2_STEPS": 750}}


def test_every_paper_names_its_report_function_and_an_existing_page():
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    for spec in PAPERS:
        assert callable(resolve(spec.reproduce)) and (root / spec.page).is_file(), spec


@pytest.mark.timeout(600)
@pytest.mark.parametrize("name", PAPERS.names())
def test_a_quick_report_runs_on_confirmation_seeds_and_judges_every_claim(name, tmp_path, monkeypatch):
    module = resolve(PAPERS[name].reproduce).__module__
    import importlib

    mod = importlib.import_module(module)
    monkeypatch.setattr(mod, "QUICK_REPS", {k: min(n, 2) for k, n in mod.QUICK_REPS.items()})  # the fewest a test takes
    for attr, value in SHORTER.get(name, {}).items():
        monkeypatch.setattr(mod, attr, value)
    result = resolve(PAPERS[name].reproduce)(quick=True, jobs=2, out=tmp_path, progress=False)
    report = (tmp_path / "report.md").read_text()
    assert "Quick run" in report and result["claims"] > 0 and (tmp_path / "parameters.md").is_file()
    with open(tmp_path / "runs.csv") as f:
        seeds = {int(r["seed"]) for r in csv.DictReader(f)}
    assert seeds and seeds <= set(CONFIRMATION_SEEDS)
    with open(tmp_path / "summary.csv") as f:
        claims = list(csv.DictReader(f))
    assert len(claims) == result["claims"] and {c["verdict"] for c in claims} <= VERDICTS
    assert sum(result["verdicts"].values()) == result["claims"]
    assert re.search(r"\| claim \| paper \| ours \(95% CI\) \| n \| test \| p \| effect \| verdict \|", report)


@pytest.mark.experiment
@pytest.mark.timeout(900)
def test_reproduce_all_quick_from_the_command_line(tmp_path):
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "swarm", "reproduce", "all", "--quick", "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=900)  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    for name in PAPERS.names():
        assert (tmp_path / name / "report.md").is_file()


def test_a_reports_parameter_page_lists_every_declared_parameter_with_its_source(tmp_path):
    from swarm.core.params import provenance
    from swarm.experiments.report import parameter_classes, parameters_page, parameters_section

    classes = parameter_classes(("cmarking", "ant", "cmarking"))
    assert len(classes) == len(set(classes)) and classes  # each class once
    page = parameters_page("T", ("cmarking", "ant"))
    for cls in classes:
        assert f"## {cls.__name__} ({cls.__module__})" in page
        for p in provenance(cls):
            assert f"| {p.name} | " in page
    title, text = parameters_section(("cmarking", "ant"))
    total = sum(len(provenance(c)) for c in classes)
    assert title == "Parameters" and text.startswith(f"{total} parameters (") and "parameters.md" in text


def test_the_index_counts_each_reports_verdicts_and_marks_quick_runs(tmp_path):
    from swarm.experiments.report import QUICK_BANNER, write_index

    first, second = PAPERS.names()[:2]
    for name, verdicts, banner in (
        (first, [REPRODUCED, REVERSED, REPRODUCED], ""),
        (second, [SAME_DIRECTION], QUICK_BANNER),
    ):
        (tmp_path / name).mkdir()
        (tmp_path / name / "report.md").write_text(f"# x\n\n{banner}\n")
        with open(tmp_path / name / "summary.csv", "w", newline="") as f:
            w = csv.DictWriter(f, ["claim", "verdict"])
            w.writeheader()
            w.writerows({"claim": str(i), "verdict": v} for i, v in enumerate(verdicts))
    lines = write_index(tmp_path).read_text().splitlines()
    row = {line.split("](")[1].split("/")[0]: line for line in lines if line.startswith("| [")}
    assert set(row) == {first, second}
    assert row[first].endswith("| 3 | 2 | 0 | 0 | 1 | 0 |") and "quick run" not in row[first]
    assert row[second].endswith("| 1 | 0 | 1 | 0 | 0 | 0 |") and "quick run" in row[second]
