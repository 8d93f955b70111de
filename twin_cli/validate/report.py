"""Renders a validation run as files: JUnit XML, Markdown, PNG plots (the CLI draws the table)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

from twin_cli.validate.checks.base import CheckResult, Status
from twin_cli.validate.runner import ValidationRun

MARK = {Status.PASS: "pass", Status.WARN: "warn", Status.FAIL: "FAIL", Status.SKIP: "skip"}
MD_MARK = {Status.PASS: "✅", Status.WARN: "⚠️", Status.FAIL: "❌", Status.SKIP: "➖"}


def label(r: CheckResult) -> str:
    return r.check if r.scenario in (None, r.check) else f"{r.check} ({r.scenario})"


def junit_xml(run: ValidationRun) -> str:
    """JUnit XML: one <testsuite> for the robot, one <testcase> per check that ran."""
    counts = run.counts()
    suite = ET.Element(
        "testsuite",
        name=f"twin validate {run.robot}",
        tests=str(len(run.results)),
        failures=str(counts["fail"]),
        errors="0",
        skipped=str(counts["skip"]),
        time=f"{run.seconds:.3f}",
    )
    for r in run.results:
        case = ET.SubElement(
            suite,
            "testcase",
            classname=f"twin.validate.{r.kind}",
            name=label(r),
            time=f"{r.seconds:.3f}",
        )
        text = "\n".join([f"measured {r.measured}; threshold {r.threshold}", *r.hints, *r.details])
        if r.status is Status.FAIL:
            failure = ET.SubElement(case, "failure", message=(r.hints or (r.measured,))[0])
            failure.text = text
        elif r.status is Status.SKIP:
            ET.SubElement(case, "skipped", message=(r.details or ("not applicable",))[0])
        else:
            ET.SubElement(case, "system-out").text = text
    root = ET.Element("testsuites", name="twin validate")
    root.append(suite)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def markdown(run: ValidationRun) -> str:
    """A Markdown summary for CI pages (e.g. $GITHUB_STEP_SUMMARY)."""
    verdict = "passed" if run.passed else "FAILED"
    lines = [
        f"## twin validate: `{run.robot}` {verdict}",
        "",
        f"Source `{run.source}`, {len(run.results)} checks in {run.seconds:.1f} s.",
        "",
        "| | check | measured | threshold |",
        "|---|---|---|---|",
    ]
    for r in run.results:
        lines.append(f"| {MD_MARK[r.status]} | {label(r)} | {r.measured} | {r.threshold} |")
    problems = [r for r in run.results if r.status in (Status.FAIL, Status.WARN)]
    if problems:
        lines += ["", "### What to fix", ""]
        for r in problems:
            for hint in r.hints or r.details:
                lines.append(f"- **{r.check}** ({r.status.value}): {hint}")
    return "\n".join(lines) + "\n"


def write_plots(run: ValidationRun, directory: str | Path) -> list[Path]:
    """One PNG per result series (free fall against ½gt², foot slip over time); Agg backend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for r in run.results:
        for series in r.series:
            fig, ax = plt.subplots(figsize=(6, 4), dpi=100)
            for label, values in series.values.items():
                style = "--" if label.startswith("½") else "-"
                ax.plot(series.t, values, style, label=label)
            ax.set_xlabel("time [s]")
            ax.set_ylabel(f"{series.label} [{series.unit}]")
            ax.set_title(f"{run.robot}: {r.check} ({r.status.value})")
            ax.grid(True, alpha=0.3)
            ax.legend()
            slug = re.sub(r"[^a-z0-9]+", "_", f"{r.check}_{series.label}".lower()).strip("_")
            path = directory / f"{slug}.png"
            fig.savefig(path)
            plt.close(fig)
            written.append(path)
    return written
