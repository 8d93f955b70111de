"""gz-stats line/CSV formatting and the client's rebuilding of server errors (pure, no server)."""

from __future__ import annotations

import re

import pytest

from twin_cli.cli.stats_format import CSV_HEADER, sample_times, stats_csv_row, stats_line
from twin_cli.errors import EntityExistsError, EntityNotFoundError, RequestError
from twin_cli.server.client import rebuild_error

# `gz stats`' line, which scripts parse: `Factor[%4.2f] SimTime[%4.2f] RealTime[%4.2f] Paused[%c]`.
GZ_LINE = re.compile(
    r"^Factor\[\d+\.\d\d\] SimTime\[\d+\.\d\d\] RealTime\[\d+\.\d\d\] Paused\[[TF]\]$"
)


def _stats(factor=1.0, sim=12.344, real=12.356, paused=False):
    return {"factor": factor, "sim_time": sim, "real_time": real, "iterations": 1, "paused": paused}


def test_stats_line_is_gz_format_with_two_decimals():
    line = stats_line(_stats())
    assert line == "Factor[1.00] SimTime[12.34] RealTime[12.36] Paused[F]", line
    assert GZ_LINE.match(line)


def test_stats_line_paused_flag_and_negative_factor_clamped_to_zero():
    line = stats_line(_stats(factor=-0.5, paused=True))
    assert line.startswith("Factor[0.00]") and line.endswith("Paused[T]"), line


def test_stats_csv_row_uses_gz_widths():
    row = stats_csv_row(_stats(factor=0.987, sim=1.5, real=1.25))
    assert row == f"0.99, {1.5:16.6f}, {1.25:16.6f}, F", row
    assert CSV_HEADER.startswith("# real-time factor")


def test_sample_times_five_a_second_until_duration():
    ticks = list(sample_times(100.0, 2.0))
    assert len(ticks) == 11, f"ticks in 2 s at 0.2 s: {len(ticks)}"
    assert ticks[0] == 100.0 and ticks[-1] == pytest.approx(102.0, abs=1e-9)
    gaps = {round(b - a, 9) for a, b in zip(ticks, ticks[1:], strict=False)}
    assert gaps == {0.2}, f"gaps between samples [s]: {gaps}"


def test_sample_times_without_duration_never_ends():
    ticks = sample_times(0.0, None)
    assert [next(ticks) for _ in range(1000)][-1] == pytest.approx(199.8)


@pytest.mark.parametrize(
    ("name", "cls"),
    [("EntityNotFoundError", EntityNotFoundError), ("EntityExistsError", EntityExistsError)],
)
def test_server_error_is_raised_again_as_the_same_class(name, cls):
    message = "Entity [r] does not exist; entities in this world: none"
    exc = rebuild_error(404, {"error": name, "message": message})
    assert type(exc) is cls and str(exc) == message


def test_unknown_or_garbled_server_error_becomes_request_error():
    exc = rebuild_error(500, {"error": "KeyError", "message": "boom"})
    assert isinstance(exc, RequestError) and "boom" in str(exc)
    exc = rebuild_error(502, "<html>bad gateway</html>")
    assert isinstance(exc, RequestError) and "HTTP 502" in str(exc)


def test_conversion_error_is_raised_again_as_conversion_error():
    from converters.errors import ConversionError, InputFileError

    exc = rebuild_error(400, {"error": "InputFileError", "message": "x.urdf: missing; fix it"})
    assert isinstance(exc, InputFileError) and isinstance(exc, ConversionError)
