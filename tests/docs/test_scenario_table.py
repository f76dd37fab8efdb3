#!/usr/bin/env python3
"""docs/scenarios.md's table of the shipped scenes against what the tool measured.

    python3 tests/docs/test_scenario_table.py docs/scenarios.md build/scenarios

Each row names a scene (`scenes/NAME.yaml`); its criteria count ("9/9 met", "6/6 required met")
and the figures it names (recall, coverage, precision, precision at 1 cell, ghost share) must be
those of build/scenarios/NAME/report.json, which ctest's scenario.NAME wrote, to the digits the
row gives. Exits 1 naming every row that drifted.
"""
import json
import re
import sys
from pathlib import Path

FIGURES = {  # the row's words -> report.json's metric
    "recall": lambda m: m["occupied_recall"],
    "coverage": lambda m: m["coverage"],
    "precision": lambda m: m["occupied_precision"],
    "precision at 1 cell": lambda m: m["within_cells"]["precision"][1],
    "ghost share": lambda m: m["ghost_share"],
}


def check_row(name, measured, report):
    problems = []
    results = report["criteria"]["results"]
    met = lambda rs: sum(r["status"] in ("pass", "acceptable") for r in rs)
    for count in re.finditer(r"(\d+)/(\d+) (required )?met", measured):
        chosen = [r for r in results if not r["optional"]] if count.group(3) else results
        actual = f"{met(chosen)}/{len(chosen)}"
        if actual != f"{count.group(1)}/{count.group(2)}":
            problems.append(f"says {count.group(0)}, the tool {actual}")
    for figure, value in re.findall(r"(?:^|, )((?:[a-z0-9]+ )*?[a-z]+) (\d\.\d+)", measured):
        if figure not in FIGURES:
            continue
        actual = FIGURES[figure](report["metrics"])
        digits = len(value.split(".")[1])
        if f"{actual:.{digits}f}" != value:
            problems.append(f"says {figure} {value}, the tool {actual:.{digits}f}")
    if not re.search(r"\d+/\d+ (required )?met|fails as expected", measured):
        problems.append("names no criteria count")
    return [f"{name}: {p}" for p in problems]


def main():
    doc, scenarios = Path(sys.argv[1]), Path(sys.argv[2])
    problems, rows = [], 0
    for line in doc.read_text().splitlines():
        row = re.match(r"\| `scenes/([\w-]+)\.yaml` \|.*\| ([^|]*) \|$", line)
        if not row:
            continue
        rows += 1
        report = scenarios / row.group(1) / "report.json"
        if not report.exists():
            problems.append(f"{row.group(1)}: no {report} (run ctest -L scenario first)")
            continue
        problems += check_row(row.group(1), row.group(2), json.loads(report.read_text()))
    shipped = sorted(p.stem for p in (doc.parent.parent / "scenes").glob("*.yaml"))
    if rows < len(shipped) - 1:  # the template is the README's, not the table's
        problems.append(f"the table has {rows} rows for {len(shipped)} shipped scenes")
    for problem in problems:
        print(f"{doc}: {problem}", file=sys.stderr)
    print(f"{rows} rows of {doc.name} checked against the tool's reports")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
