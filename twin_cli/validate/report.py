"""Renders a validation run as files: JUnit XML, Markdown, PNG plots (the CLI draws the table)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING

from twin_cli.validate.checks.base import CheckResult, Series, Status
from twin_cli.validate.markdown_text import cell, inline
from twin_cli.validate.runner import ValidationRun

if TYPE_CHECKING:
    from matplotlib.figure import Figure

MARK = {
    Status.PASS: "pass",
    Status.WARN: "warn",
    Status.FAIL: "FAIL",
    Status.NOT_APPLICABLE: "n/a",
    Status.ERROR: "ERROR",
}
MD_MARK = {
    Status.PASS: "✅",
    Status.WARN: "⚠️",
    Status.FAIL: "❌",
    Status.NOT_APPLICABLE: "➖",
    Status.ERROR: "💥",
}
TO_FIX = (Status.ERROR, Status.FAIL, Status.WARN)  # statuses whose hints a report lists


def label(r: CheckResult) -> str:
    return r.check if r.scenario in (None, r.check) else f"{r.check} ({r.scenario})"


def junit_xml(run: ValidationRun) -> str:
    """JUnit XML: one <testsuite> for the robot, one <testcase> per check that ran."""
    counts = run.counts()
    suite = ET.Element(
        "testsuite",
        name=f"twin validate {run.robot}",
        tests=str(len(run.results)),
        failures=str(counts[Status.FAIL.value]),
        errors=str(counts[Status.ERROR.value]),
        skipped=str(counts[Status.NOT_APPLICABLE.value]),
        time=f"{run.seconds:.3f}",
    )
    for r in run.results:
        junit_case(suite, r, f"twin.validate.{r.kind}", label(r))
    root = ET.Element("testsuites", name="twin validate")
    root.append(suite)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def junit_case(suite: ET.Element, r: CheckResult, classname: str, name: str) -> ET.Element:
    """One <testcase>: a robot that breaks the check is a <failure>, a check that crashed an
    <error> (a twin bug), a check that does not apply <skipped> with its reason."""
    case = ET.SubElement(suite, "testcase", classname=classname, name=name, time=f"{r.seconds:.3f}")
    text = "\n".join([f"measured {r.measured}; threshold {r.threshold}", *r.hints, *r.details])
    if r.status is Status.FAIL:
        ET.SubElement(case, "failure", message=(r.hints or (r.measured,))[0]).text = text
    elif r.status is Status.ERROR:
        kind = r.measured.removeprefix("crashed: ").split(":")[0]
        ET.SubElement(case, "error", message=r.measured, type=kind).text = text
    elif r.status is Status.NOT_APPLICABLE:
        ET.SubElement(case, "skipped", message=(r.details or ("not applicable",))[0])
    else:
        ET.SubElement(case, "system-out").text = text
    return case


def markdown(run: ValidationRun, plots: str | None = None) -> str:
    """A Markdown summary for CI pages (e.g. $GITHUB_STEP_SUMMARY); with `plots` (the plot
    directory as the page should link it), each plot is embedded below the table."""
    verdict = "passed" if run.passed else ("CRASHED" if run.exit_code == 70 else "FAILED")
    lines = [
        f"## twin validate: `{run.robot}` {verdict}",
        "",
        f"Source `{run.source}`, {len(run.results)} checks in {run.seconds:.1f} s.",
        "",
        "| | check | measured | threshold |",
        "|---|---|---|---|",
    ]
    for r in run.results:
        cells = (MD_MARK[r.status], label(r), r.measured, r.threshold)
        lines.append("| " + " | ".join(cell(c) for c in cells) + " |")
    problems = [r for r in run.results if r.status in TO_FIX]
    if problems:
        lines += ["", "### What to fix", ""]
        for r in problems:
            for hint in r.hints or r.details:
                lines.append(f"- **{r.check}** ({r.status.value}): {inline(hint)}")
    if plots is not None:
        pictures = [(r, s) for r in run.results for s in r.series]
        if pictures:
            lines += ["", "### Plots", ""]
        for r, series in pictures:
            lines.append(f"![{label(r)}: {series.label}]({plots}/{plot_name(r, series.label)})")
    return "\n".join(lines) + "\n"


def plot_name(r: CheckResult, series_label: str) -> str:
    """The PNG file name of one result's series."""
    slug = re.sub(r"[^a-z0-9]+", "_", f"{r.check}_{series_label}".lower()).strip("_")
    return f"{slug}.png"


def write_plots(run: ValidationRun, directory: str | Path) -> list[Path]:
    """One PNG per result series, written atomically (a temporary file renamed into place)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written, fig = [], None
    for r in run.results:
        for series in r.series:
            fig = figure(run.robot, r, series, reuse=fig)
            path = directory / plot_name(r, series.label)
            tmp = path.with_suffix(".png.tmp")
            fig.savefig(tmp, format="png")
            tmp.replace(path)
            written.append(path)
    if fig is not None:
        plt.close(fig)
    return written


def figure(robot: str, r: CheckResult, series: Series, reuse: Figure | None = None) -> Figure:
    """The picture of what a check measured with its threshold drawn: curves over time (free
    fall against ½gt², slip, energy...) or one bar per item (joint, sensor), the threshold as a
    red dotted line or the allowed band in green; Agg backend, 6×4 in at 100 dpi."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if reuse is None:
        fig = plt.figure(figsize=(6, 4), dpi=100)
    else:  # one canvas for many plots: its renderer's text-size cache stays warm
        fig = reuse
        fig.clear()
    ax = fig.add_subplot()
    if series.categories:
        ax.bar(series.t, next(iter(series.values.values())), color="tab:blue", label="measured")
        ax.set_xticks(series.t, series.categories, rotation=30, ha="right", fontsize=8)
        ax.set_xlim(-1.0, max(len(series.t), 2))  # one bar stays a bar, not a block
    else:
        for name, values in series.values.items():
            ax.plot(series.t, values, "--" if name.startswith("½") else "-", label=name)
    if series.band is not None:
        low, high = series.band
        ax.fill_between(series.t, low, high, color="green", alpha=0.2, label="allowed")
    if series.threshold is not None:
        ax.axhline(series.threshold, color="red", linestyle=":", label="threshold")
    if series.log:
        ax.set_yscale("log")
    elif series.threshold is not None:
        ax.set_ylim(*_span(series))
    ax.set_xlabel(series.x_label)
    ax.set_ylabel(f"{series.label} [{series.unit}]")
    ax.set_title(f"{robot}: {r.check} ({r.status.value})")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()  # keeps long axis labels and rotated names inside the picture
    return fig


def _span(series: Series) -> tuple[float, float]:
    """Linear value-axis limits that show both the values and the threshold: a check far
    inside its limit (all zeros, say) would otherwise autoscale the threshold out of view."""
    import numpy as np

    values = np.concatenate([np.asarray(v, dtype=float) for v in series.values.values()])
    values = values[np.isfinite(values)]
    low = min(float(values.min(initial=0.0)), 0.0, float(series.threshold))
    high = max(float(values.max(initial=0.0)), float(series.threshold))
    pad = 0.08 * ((high - low) or abs(float(series.threshold)) or 1.0)
    return low - pad, high + pad
