"""`twin validate ROBOT... --sweep NAME=LO:HI:N`: the checklist on every robot × variant.

The command side of `twin_cli.validate.sweep`: progress (a rich bar on a terminal, one plain
line per variant when piped, nothing with --json), the matrix, and the report files.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

SweepOpt = Annotated[
    list[str] | None,
    typer.Option(
        "--sweep",
        help="Sweep a parameter: NAME=LO:HI:N (repeatable; the grid of all). NAME: ground_mu, "
        "foot_mu, foot_friction_scale, friction_scale, mass_scale, gravity, damping_scale, "
        "kp_scale.",
    ),
]
JobsOpt = Annotated[
    int | None, typer.Option("--jobs", help="Worker processes for a sweep (default: all cores).")
]
RayOpt = Annotated[
    str | None,
    typer.Option("--ray", help="Run the sweep on a Ray cluster: auto or HOST:PORT (twin[ray])."),
]


def run_sweep(
    robots: list[Path],
    sweeps: list[str],
    options: dict,
    *,
    jobs: int | None,
    ray: str | None,
    json: bool,
    junit: Path | None,
    markdown: Path | None,
    plots: Path | None,
) -> None:
    """Parse the axes, run the sweep with progress, print the matrix, write the reports."""
    from twin_cli.cli.output import Output
    from twin_cli.validate import sweep_report as render
    from twin_cli.validate.sweep import parse_axis, sweep

    axes = [parse_axis(text) for text in sweeps]
    out = Output(json)
    with _progress(out) as on_done:
        result = sweep(
            [str(r) for r in robots], axes, options=options, jobs=jobs, ray=ray, on_done=on_done
        )
    if json:
        out.data(result.to_dict())
    else:
        _print_matrix(result, out)
    if junit:
        write_report(junit, render.junit_xml(result))
    if markdown:
        write_report(markdown, render.markdown(result))
    if plots:
        path = render.write_margin_plot(result, Path(plots) / "sweep_margins.png")
        out.line(f"plot: {path}")
    raise typer.Exit(result.exit_code)


def check_report_targets(*paths: Path | None) -> None:
    """Refuses a report path that is a directory, device or pipe before any check runs (its
    Markdown folder is made): a long run must not end in a file it cannot write.

    Raises:
        OutputFileError: exit 2, naming the path.
    """
    from twin_cli.files.output_files import checked_target

    for path in paths:
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
            checked_target(path)


def write_report(path: Path, text: str) -> None:
    """Atomically, to a regular file only (`twin_cli.files.output_files`), readable by others."""
    from twin_cli.files.output_files import REPORT, write_atomically

    write_atomically(path, text.encode("utf-8"), REPORT)


class _progress:
    """A context giving the `on_done(run, done, total)` callback for the sweep."""

    def __init__(self, out: Any) -> None:
        self.out = out
        self.bar: Any = None
        self.task: Any = None

    def __enter__(self):
        if self.out.is_tty and not self.out.json_mode:
            from rich.progress import Progress

            self.bar = Progress(transient=True)
            self.bar.start()
        return self.on_done

    def on_done(self, run: Any, done: int, total: int) -> None:
        from twin_cli.validate.sweep_report import variant_name

        verdict = "pass" if run.passed else "FAIL"
        if self.bar is not None:
            if self.task is None:
                self.task = self.bar.add_task("twin validate sweep", total=total)
            self.bar.update(self.task, completed=done)
            line = f"{run.robot} [{variant_name(run)}]: {verdict}"
            self.bar.console.print(line, markup=False, highlight=False)
        else:
            self.out.line(f"[{done}/{total}] {run.robot} {variant_name(run)}: {verdict}")

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.stop()


def _print_matrix(result: Any, out: Any) -> None:
    from twin_cli.validate.report import MARK, label
    from twin_cli.validate.sweep_report import variant_name

    checks = list(dict.fromkeys(label(r) for run in result.runs for r in run.results))
    rows = []
    for run in result.runs:
        by_check = {label(r): MARK[r.status] for r in run.results}
        rows.append([run.robot, variant_name(run), *(by_check.get(c, "") for c in checks)])
    out.table("twin validate sweep", ["robot", "variant", *checks], rows)
    failed = sum(not r.passed for r in result.runs)
    out.line(
        f"{len(result.runs)} variants, {failed} failing, on {result.executor} "
        f"in {result.seconds:.1f} s"
    )
