"""A reader that closes the pipe early (`twin list | head -1`) ends the command quietly, exit 0."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from twin_cli.spawn_request import SpawnRequest

BALL = (
    '<sdf version="1.6"><model name="b"><link name="l"><collision name="c"><geometry>'
    "<sphere><radius>0.1</radius></sphere></geometry></collision></link></model></sdf>"
)


@pytest.fixture(scope="module")
def world(tmp_path_factory, serve_world):
    with serve_world(tmp_path_factory.mktemp("rt"), "pipe") as (client, proc):
        client.spawn_batch(
            SpawnRequest(xml=BALL),
            poses=[{"x": float(i), "z": 1.0} for i in range(20)],
            base="ball",
        )
        yield client


@pytest.mark.parametrize(
    "args",
    [
        ["list"],
        ["list", "--json"],
        ["stats", "-d", "0.3"],
        ["joints", "ball_0"],
        ["topics"],
        ["topics", "echo", "/clock"],
        ["topics", "echo", "/tf", "--json"],
        ["model", "ball_0"],
        ["spawn", "--help"],
    ],
)
def test_a_closed_pipe_ends_the_command_with_exit_0_and_no_traceback(world, args) -> None:
    read, write = os.pipe()
    os.close(read)  # the reader is gone before the command writes a byte
    try:
        done = subprocess.run(
            [sys.executable, "-m", "twin_cli", *args, "--world", "pipe"],
            stdout=write,
            stderr=subprocess.PIPE,
            text=True,
            timeout=60,
            env={**os.environ},
        )
    finally:
        os.close(write)
    assert done.returncode == 0, f"twin {' '.join(args)}: exit {done.returncode}: {done.stderr}"
    assert "Traceback" not in done.stderr and "Error" not in done.stderr, done.stderr
