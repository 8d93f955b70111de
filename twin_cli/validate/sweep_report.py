"""Renders a sweep: JUnit (a test case per robot × variant × check), a Markdown pass/fail
matrix, and a PNG of each check's margin across each swept parameter."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from twin_cli.validate.checks.base import Status
from twin_cli.validate.margins import MARGINS, margin
from twin_cli.validate.markdown_text import cell
from twin_cli.validate.report import MD_MARK, junit_case, label
from twin_cli.validate.sweep import SweepRun, VariantRun


def variant_name(run: VariantRun) -> str:
    """`foot_mu=0.3 gravity=9.81` (or "nominal" when nothing is swept)."""
    return " ".join(f"{k}={v:g}" for k, v in run.values.items()) or "nominal"


def junit_xml(sweep: SweepRun) -> str:
    """One <testsuite> per robot × variant, one <testcase> per check."""
    root = ET.Element("testsuites", name="twin validate sweep")
    for run in sweep.runs:
        suite = ET.SubElement(
            root,
            "testsuite",
            name=f"twin validate {run.robot} [{variant_name(run)}]",
            tests=str(len(run.results)),
            failures=str(sum(r.failed for r in run.results)),
            errors=str(sum(r.errored for r in run.results)),
            skipped=str(sum(r.status is Status.NOT_APPLICABLE for r in run.results)),
            time=f"{run.seconds:.3f}",
        )
        for r in run.results:
            junit_case(suite, r, f"twin.validate.{run.robot}", f"{label(r)} [{variant_name(run)}]")
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def markdown(sweep: SweepRun) -> str:
    """A pass/fail matrix: one row per robot × variant, one column per check."""
    checks = _checks(sweep)
    verdict = "passed" if sweep.passed else "FAILED"
    failed = sum(not r.passed for r in sweep.runs)
    lines = [
        f"## twin validate sweep {verdict}",
        "",
        f"{len(sweep.runs)} variants ({failed} failing) on {sweep.executor} "
        f"in {sweep.seconds:.1f} s.",
        "",
        "| robot | variant | " + " | ".join(cell(c) for c in checks) + " |",
        "|---|---|" + "---|" * len(checks),
    ]
    for run in sweep.runs:
        by_check = {label(r): r for r in run.results}
        cells = [MD_MARK[by_check[c].status] if c in by_check else "" for c in checks]
        row = [run.robot, variant_name(run), *cells]
        lines.append("| " + " | ".join(cell(c) for c in row) + " |")
    return "\n".join(lines) + "\n"


def _checks(sweep: SweepRun) -> list[str]:
    seen: dict[str, None] = {}
    for run in sweep.runs:
        for r in run.results:
            seen.setdefault(label(r), None)
    return list(seen)


def write_margin_plot(sweep: SweepRun, path: str | Path) -> Path:
    """One PNG: a row per check, a column per swept parameter; each check's margin (or pass=1 /
    fail=0) against the parameter, a line per robot, with the margin's zero line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    checks, axes = _checks(sweep), [a.name for a in sweep.axes] or ["variant"]
    fig, grid = plt.subplots(
        len(checks), len(axes), figsize=(5 * len(axes), 2.6 * len(checks)), squeeze=False, dpi=100
    )
    for row, check in enumerate(checks):
        for col, axis in enumerate(axes):
            _panel(grid[row][col], sweep, check, axis)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    fig.savefig(tmp, format="png")
    plt.close(fig)
    tmp.replace(path)
    return path


def _panel(ax, sweep: SweepRun, check: str, axis: str) -> None:
    unit = ""
    for robot in dict.fromkeys(r.robot for r in sweep.runs):
        xs, ys, fails = [], [], []
        for i, run in enumerate(r for r in sweep.runs if r.robot == robot):
            r = next((x for x in run.results if label(x) == check), None)
            if r is None:
                continue
            m = margin(r, run.limits.get(r.check))
            xs.append(run.values.get(axis, float(i)))
            broken = r.failed or r.errored
            ys.append(m if m is not None else float(not broken))
            fails.append(broken)
            unit = MARGINS[r.check][0] if m is not None else "pass (1) / fail (0)"
        ax.plot(xs, ys, "o-", label=robot)
        ax.plot(
            [x for x, f in zip(xs, fails, strict=True) if f],
            [y for y, f in zip(ys, fails, strict=True) if f],
            "rx",
            markersize=10,
        )
    ax.axhline(0.0, color="k", linewidth=0.8, linestyle="--")
    ax.set_title(f"{check}\nmargin = threshold − measured; > 0 passes", fontsize="small")
    ax.set_xlabel(axis)
    ax.set_ylabel(f"margin [{unit}]" if "/" not in unit else unit)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small")
